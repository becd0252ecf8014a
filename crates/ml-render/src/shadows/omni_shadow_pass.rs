//! Point-light shadows (docs/DESIGN.md#point-light-shadows): every frame, before shading, the
//! shadowed lights' cubes are rendered where the lights are now. The cube array is a shadow
//! store (the shading passes sample it through the scene's texture set); this pass records
//! its rendering in the mode the settings chose (omni_shadow.rs).

use crate::error::RenderError;
use crate::frame_resources::FrameResources;
use crate::pass::{FrameWork, Pass, Prepare, Recording};
use crate::shadows::stores::SharedShadows;
use crate::sync::Use;
use ml_vk::{Context, VkError};

pub struct OmniShadowPass {
    shadows: SharedShadows,
    /// What its drawing does to the cube array (OmniShadows::cube_use).
    cubes: Option<Use>,
}

impl OmniShadowPass {
    pub fn new(shadows: SharedShadows) -> OmniShadowPass {
        let cubes = shadows.borrow().omni.cube_use();
        OmniShadowPass { shadows, cubes }
    }
}

impl Pass for OmniShadowPass {
    fn timer_name(&self) -> Option<&'static str> {
        Some("omni shadows")
    }

    fn uses(&self) -> Vec<Use> {
        self.cubes.into_iter().collect()
    }

    fn bind_frame(&mut self, _: &Context, _: &FrameResources) -> Result<(), VkError> {
        Ok(())
    }

    fn record(&self, rec: &Recording) {
        let omni = &self.shadows.borrow().omni;
        omni.record(rec.ctx, rec.cmd, omni.placed(), (&rec.scene.meshes, rec.objects));
    }

    fn destroy(&mut self, _: &Context) {}

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for OmniShadowPass {
    fn prepare(&mut self, p: &mut Prepare) -> Result<(), RenderError> {
        self.shadows.borrow_mut().omni.place(p.rest_lights, p.light_offset);
        Ok(())
    }
}
