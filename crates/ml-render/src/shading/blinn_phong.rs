//! The blinn-phong model's lights beside the point lights — the sun, the spot, the ambient
//! colour — and its texture transform, as a scene part: the frame uniforms they fill.

use crate::descriptors::Resource;
use crate::error::RenderError;
use crate::scene_part::{OwnedPart, ScenePart};
use ml_cpu::blinn_phong::BlinnPhongLights;
use ml_cpu::gpu_types::FrameUniforms;
use ml_cpu::scene::Scene;
use ml_vk::Context;

impl ScenePart for BlinnPhongLights {
    fn resource(&self, _name: &str) -> Option<Resource> {
        None
    }

    /// The sun's xyz; its w are the shadow stores' (the sun map's texel sizes).
    fn frame_uniforms(&self, uniforms: &mut FrameUniforms) {
        uniforms.sun_direction[..3].copy_from_slice(&self.sun_direction.to_array());
        uniforms.sun_strength[..3].copy_from_slice(&self.sun_strength.to_array());
        uniforms.spot_position_range = self.spot.position.extend(self.spot.range).to_array();
        uniforms.spot_direction_power = self.spot.direction.extend(self.spot.power).to_array();
        uniforms.spot_strength = self.spot.strength.extend(0.0).to_array();
        uniforms.ambient_light = self.ambient.extend(0.0).to_array();
        uniforms.texture_transform = self.texture_transform.to_cols_array();
    }
}

impl OwnedPart for BlinnPhongLights {}

/// The scene's blinn-phong lights (a copy: the renderer never changes them), as a scene part.
pub fn make_part(_ctx: &Context, scene: &Scene) -> Result<Box<dyn OwnedPart>, RenderError> {
    Ok(Box::new(scene.blinn_phong))
}
