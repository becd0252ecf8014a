//! Point-light shadows drawn by compute shaders (`--omni-shadow compute` and `atlas`;
//! docs/DESIGN.md#compute-shadow-raster). The graphics modes are bound by filling 6 × size²
//! texels per light on the few SMs that run graphics work; here the whole GPU draws them:
//! each frame the compute shadow raster (shadow_raster.rs) draws every shadowed light's six
//! faces into the cube array the shading passes sample, which ends as the graphics modes
//! leave it — or the faces the frame's plan lists into the shadow atlas (shadow_atlas.rs).

use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::meshlet_scene::MeshletGeometryView;
use crate::omni_shadow::NEAR_FRACTION;
use crate::pass::{Pass, Recording, SlotReport};
use crate::report::OmniRasterStats;
use crate::shadow_atlas::tile_table;
use crate::shadow_raster::{ShadowRaster, ShadowTarget, ShadowViews};
use gpu_allocator::MemoryLocation;
use ml_cpu::gpu_types::OmniRasterCounters;
use ml_vk::commands::copy_buffer_to_host;
use ml_vk::{vk, Buffer, Context, VkError};

pub struct OmniShadowCompute {
    views: ShadowViews,
    raster: ShadowRaster,
    /// The counters, copied out at the end of the pass, per frame slot.
    readback: Vec<Buffer>,
}

impl OmniShadowCompute {
    pub fn new(
        ctx: &Context,
        geometry: MeshletGeometryView,
        (views, size, large_capacity): (ShadowViews, u32, u32),
    ) -> Result<OmniShadowCompute, VkError> {
        let raster = ShadowRaster::new(ctx, geometry, (views, size, large_capacity), FRAMES_IN_FLIGHT)?;
        let pass = OmniShadowCompute { views, raster, readback: Vec::new() };
        ml_vk::build(ctx, pass, |p| {
            for _ in 0..FRAMES_IN_FLIGHT {
                let bytes = size_of::<OmniRasterCounters>() as u64;
                let readback = Buffer::new(
                    ctx,
                    "shadow raster counters read-back",
                    bytes,
                    vk::BufferUsageFlags::TRANSFER_DST,
                    MemoryLocation::GpuToCpu,
                )?;
                p.readback.push(readback);
            }
            Ok(())
        })
    }
}

impl Pass for OmniShadowCompute {
    fn timer_name(&self) -> Option<&'static str> {
        Some("omni shadows")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let named = |name| frame.raw_buffer(name).expect("the scene's buffers are in every frame's table");
        self.raster.bind(ctx, frame.slot, (named("ObjectBuffer"), named("AlphaMaskBuffer")))
    }

    fn record(&self, rec: &Recording) {
        let lights: Vec<[f32; 4]> =
            rec.shadowed.iter().take(self.views.lights() as usize).map(|l| l.position.extend(l.radius).to_array()).collect();
        if lights.is_empty() {
            return;
        }
        // Every face's projection: 90°, in the light's frame in radii.
        let projection = glam::Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, NEAR_FRACTION, 1.0);
        let readers = vk::PipelineStageFlags::FRAGMENT_SHADER | vk::PipelineStageFlags::COMPUTE_SHADER;
        match (self.views, rec.atlas) {
            (ShadowViews::Atlas { .. }, Some(plan)) => {
                let tiles = tile_table(plan, lights.len());
                self.raster.record_atlas(rec.ctx, rec.cmd, rec.slot, (&lights, &tiles), projection, readers);
            }
            _ => {
                let target = ShadowTarget { image: rec.scene.omni.cubes.raw, readers };
                self.raster.record(rec.ctx, rec.cmd, rec.slot, &lights, projection, &target);
            }
        }
        let counter_bytes = size_of::<OmniRasterCounters>() as u64;
        copy_buffer_to_host(rec.ctx, rec.cmd, (self.raster.counters.raw, self.readback[rec.slot].raw), counter_bytes);
    }

    fn collect(&self, slot: usize, report: &mut SlotReport) {
        let c: OmniRasterCounters = bytemuck::pod_read_unaligned(&self.readback[slot].mapped()[..size_of::<OmniRasterCounters>()]);
        report.omni_raster = Some(OmniRasterStats {
            pairs: c.pairs[3],
            small: c.drawn[0].saturating_sub(c.drawn[1]),
            large: c.large[3],
            in_place: c.drawn[1],
            texels: c.drawn[2],
            pairs_in_place: c.drawn[3],
        });
    }

    fn destroy(&mut self, ctx: &Context) {
        self.raster.destroy(ctx);
        for b in &mut self.readback {
            b.destroy(ctx);
        }
        self.readback.clear();
    }
}

impl ml_vk::Release for OmniShadowCompute {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
