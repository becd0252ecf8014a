//! Debug views shadow-map and shadow-cube: paint the sun's shadow map (or the first shadowed
//! light's cube, unfolded as a cross) over whatever the technique drew. Untimed.

use crate::compute_pass::ComputePass;
use crate::pass::{FrameResources, Pass, Recording};
use crate::scene_gpu::SceneGpu;
use ml_vk::{Context, VkError};

pub struct ShadowMapView {
    pass: ComputePass,
}

impl ShadowMapView {
    /// `cube`: the point-light cube instead of the sun's map (constant_id 0, CUBE).
    pub fn new(ctx: &Context, scene: &SceneGpu, cube: bool) -> Result<ShadowMapView, VkError> {
        let constants = [(0, u32::from(cube))];
        let pass = ComputePass::new(ctx, &[scene.textures.set_layout.raw], (&ml_shaders::DEBUG_SHADOW_MAP_COMP, &constants))?;
        Ok(ShadowMapView { pass })
    }
}

impl Pass for ShadowMapView {
    fn timer_name(&self) -> Option<&'static str> {
        None
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.pass.bind_frame(ctx, frame, &|_| None)
    }

    fn record(&self, rec: &Recording) {
        let sets = [rec.scene.textures.set];
        self.pass.record_into_colour_target(rec.ctx, rec.cmd, (rec.slot, &sets), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
