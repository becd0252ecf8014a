//! Debug views shadow-map, shadow-cube and shadow-atlas: paint the sun's shadow map (or the
//! first shadowed light's cube, unfolded as a cross, or the shadow atlas) over whatever the
//! technique drew. Untimed.

use crate::compute_pass::ComputePass;
pub(crate) use crate::debug_view::ShownStore;
use crate::frame_resources::FrameResources;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shadows::stores::ShadowStores;
use crate::sync::{shadow_reads, Use};
use ml_vk::{vk, Context, VkError};

pub struct ShadowMapView {
    pass: ComputePass,
}

impl ShadowMapView {
    /// `shown`: the sun's map, the point-light cube (constant CUBE) or the shadow atlas
    /// (ATLAS, and its blocks: ATLAS_BLOCKS, ATLAS_SIDE, ATLAS_COLUMNS, ATLAS_ROWS).
    pub fn new(ctx: &Context, scene: &SceneGpu, shadows: &ShadowStores, shown: ShownStore) -> Result<ShadowMapView, VkError> {
        let blocks = shadows.omni.atlas.blocks().filter(|_| shown == ShownStore::Atlas);
        let constants = [
            ("CUBE", u32::from(shown == ShownStore::Cube)),
            ("ATLAS", u32::from(blocks.is_some())),
            ("ATLAS_BLOCKS", blocks.map_or(1, |b| b.count)),
            ("ATLAS_SIDE", blocks.map_or(1, |b| b.side)),
            ("ATLAS_COLUMNS", blocks.map_or(1, |b| b.columns)),
            ("ATLAS_ROWS", blocks.map_or(1, |b| b.extent()[1] / b.side)),
        ];
        let pass = ComputePass::new(ctx, &[scene.textures.set_layout.raw], (&ml_shaders::DEBUG_SHADOW_MAP_COMP, &constants))?;
        Ok(ShadowMapView { pass })
    }
}

impl Pass for ShadowMapView {
    fn timer_name(&self) -> Option<&'static str> {
        None
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.pass.bind_frame(ctx, frame)
    }

    fn uses(&self) -> Vec<Use> {
        let mut uses = shadow_reads(vk::PipelineStageFlags::COMPUTE_SHADER);
        uses.push(ComputePass::colour_use());
        uses
    }

    fn record(&self, rec: &Recording) {
        let sets = [rec.scene.textures.set];
        self.pass.record_into_colour_target(rec.ctx, rec.cmd, (rec.slot, &sets), rec.targets.color.raw, rec.extent);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.pass.destroy(ctx);
    }
}
