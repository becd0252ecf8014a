//! Point-light shadows drawn by compute shaders (`--omni-shadow compute` and `atlas`;
//! docs/DESIGN.md#compute-shadow-raster). The graphics modes are bound by filling 6 × size²
//! texels per light on the few SMs that run graphics work; here the whole GPU draws them:
//! each frame the compute shadow raster (shadow_raster.rs) draws every shadowed light's six
//! faces into the cube array the shading passes sample, which ends as the graphics modes
//! leave it — or the faces the frame's plan lists into the shadow atlas (shadow_atlas.rs).

use crate::error::RenderError;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{FrameWork, Pass, Prepare, Recording, SlotReport};
use crate::read_back::{HostRead, ReadBack};
use crate::report::{FeatureStats, FrameStats};
use crate::scene::meshlets::MeshletGeometryView;
use crate::scene::{ALPHA_MASKS, OBJECTS};
use crate::shadows::omni_shadow::{OmniShadows, NEAR_FRACTION};
use crate::shadows::shadow_atlas::tile_table;
use crate::shadows::shadow_raster::{ShadowRaster, ShadowTarget, ShadowViews};
use crate::shadows::stores::SharedShadows;
use crate::sync::{Use, SHADOW_ATLAS, SHADOW_CUBES, SHADOW_RASTER_COUNTERS};
use ml_cpu::gpu_types::OmniRasterCounters;
use ml_cpu::shadow_atlas::{AtlasPlan, PlannedLight};
use ml_vk::{vk, Context, VkError};

pub struct OmniShadowCompute {
    shadows: SharedShadows,
    views: ShadowViews,
    raster: ShadowRaster,
    /// The counters, copied at the end of the frame, per frame slot.
    readback: ReadBack,
    /// The shadow atlas's plan for the frame being recorded (the atlas views).
    plan: Option<AtlasPlan>,
}

impl OmniShadowCompute {
    pub fn new(
        ctx: &Context,
        (geometry, shadows): (MeshletGeometryView, SharedShadows),
        (views, size, large_capacity): (ShadowViews, u32, u32),
    ) -> Result<OmniShadowCompute, RenderError> {
        let raster = ShadowRaster::new(ctx, geometry, (views, size, large_capacity), FRAMES_IN_FLIGHT)?;
        let readback = ReadBack::new("shadow raster counters read-back");
        let pass = OmniShadowCompute { shadows, views, raster, readback, plan: None };
        ml_vk::build(ctx, pass, |p| Ok(p.readback.make_all(ctx, size_of::<OmniRasterCounters>() as u64)?))
    }

    /// The lights the frame draws (position and radius each): the placed ones the views
    /// hold, none where an atlas frame has no plan (the atlas keeps what it holds).
    fn drawn_lights(&self, omni: &OmniShadows) -> Vec<[f32; 4]> {
        if matches!(self.views, ShadowViews::Atlas { .. }) && self.plan.is_none() {
            return Vec::new();
        }
        omni.placed().iter().take(self.views.lights() as usize).map(|l| l.position.extend(l.radius).to_array()).collect()
    }
}

impl Pass for OmniShadowCompute {
    fn timer_name(&self) -> Option<&'static str> {
        Some("omni shadows")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let named = |name| frame.raw_buffer(name).expect("the scene's buffers are in every frame's table");
        self.raster.bind(ctx, frame.slot, (named(OBJECTS), named(ALPHA_MASKS)))
    }

    /// The cubes, overwritten by a copy (left TRANSFER_DST_OPTIMAL); or the atlas's table,
    /// written by transfers, and the atlas, cleared and drawn by compute shaders. The
    /// raster's counters: written by transfers and shaders, dispatched from.
    fn uses(&self) -> Vec<Use> {
        use vk::AccessFlags as A;
        use vk::PipelineStageFlags as S;
        let transfer = (S::TRANSFER, A::TRANSFER_WRITE);
        let rw = A::SHADER_READ | A::SHADER_WRITE;
        let counters = (S::TRANSFER | S::COMPUTE_SHADER | S::DRAW_INDIRECT, A::TRANSFER_WRITE | rw | A::INDIRECT_COMMAND_READ);
        let mut uses = match self.views {
            ShadowViews::Atlas { .. } => {
                let [atlas, table] = SHADOW_ATLAS;
                vec![Use::buffer(table, transfer), Use::buffer(atlas, (S::COMPUTE_SHADER, rw))]
            }
            _ => vec![Use::overwriting(SHADOW_CUBES, transfer, vk::ImageLayout::TRANSFER_DST_OPTIMAL)],
        };
        uses.push(Use::buffer(SHADOW_RASTER_COUNTERS, counters));
        uses
    }

    fn record(&self, rec: &Recording) {
        let shadows = self.shadows.borrow();
        let lights = self.drawn_lights(&shadows.omni);
        if lights.is_empty() {
            return;
        }
        // Every face's projection: 90°, in the light's frame in radii.
        let projection = glam::Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, NEAR_FRACTION, 1.0);
        // Only atlas frames have a plan (an atlas frame without one draws nothing).
        match &self.plan {
            Some(plan) => {
                let tiles = tile_table(plan, lights.len());
                self.raster.record_atlas(rec.ctx, rec.cmd, rec.slot, (&lights, &tiles), projection);
            }
            None => {
                let target = ShadowTarget { image: shadows.omni.cubes.raw, readers: None };
                self.raster.record(rec.ctx, rec.cmd, rec.slot, &lights, projection, &target);
            }
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        self.raster.destroy(ctx);
        self.readback.destroy(ctx);
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for OmniShadowCompute {
    /// The raster's counters, where the frame drew (the slot's copy keeps what it had
    /// otherwise).
    fn host_reads(&self, slot: usize) -> Vec<HostRead> {
        if self.drawn_lights(&self.shadows.borrow().omni).is_empty() {
            return Vec::new();
        }
        vec![self.readback.of(slot, SHADOW_RASTER_COUNTERS, self.raster.counters.raw)]
    }

    fn prepare(&mut self, p: &mut Prepare) -> Result<(), RenderError> {
        let mut shadows = self.shadows.borrow_mut();
        let omni = &mut shadows.omni;
        omni.place(p.rest_lights, p.light_offset);
        if let ShadowViews::Atlas { .. } = self.views {
            self.plan = plan_atlas(omni, p)?;
        }
        Ok(())
    }

    fn collect(&self, slot: usize, _: &mut SlotReport, stats: &mut FrameStats) {
        let c: OmniRasterCounters = self.readback.read(slot);
        stats.set_feature(OmniRasterStats {
            pairs: c.pairs[3],
            small: c.drawn[0].saturating_sub(c.drawn[1]),
            large: c.large[3],
            in_place: c.drawn[1],
            texels: c.drawn[2],
            pairs_in_place: c.drawn[3],
        });
    }
}

/// The shadow atlas's plan for the frame's placed lights (keys: their scene indices), its
/// figures reported in the frame's statistics; None without an atlas.
fn plan_atlas(omni: &mut OmniShadows, p: &mut Prepare) -> Result<Option<AtlasPlan>, RenderError> {
    let Some(atlas) = omni.settings.and_then(|o| o.atlas()) else { return Ok(None) };
    let lights: Vec<(u32, PlannedLight)> =
        omni.chosen().iter().zip(omni.placed()).map(|(&i, l)| (i, PlannedLight { position: l.position, radius: l.radius })).collect();
    let size = (p.view.width, p.view.height);
    let Some(plan) = omni.atlas.plan(&lights, &p.view.camera, size, atlas) else { return Ok(None) };
    let plan = plan.map_err(|e| {
        RenderError::Invalid(format!(
            "shadow atlas: {e} (a budget of {} MiB; more would hold them, or fewer shadowed lights)",
            atlas.budget_mib
        ))
    })?;
    let (budget, shadow_bytes, atlas_bytes) = omni.atlas.memory();
    p.stats.set_feature(AtlasStats {
        faces: plan.tiles.len(),
        redrawn: plan.redrawn(),
        divided_by: plan.divided_by,
        budget,
        shadow_bytes,
        atlas_bytes,
        tile_bytes: plan.used_bytes(),
    });
    Ok(Some(plan))
}

impl ml_vk::Release for OmniShadowCompute {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// What one frame's compute shadow raster drew (--omni-shadow compute and atlas).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OmniRasterStats {
    /// (meshlet instance, cube face) pairs the culling kept.
    pub pairs: u32,
    /// Triangles drawn by one thread each; large ones (a work group each, or, past the
    /// list's capacity, `in_place` by the thread that found them).
    pub small: u32,
    pub large: u32,
    pub in_place: u32,
    /// Texels covered (hidden ones too).
    pub texels: u32,
    /// (meshlet instance, face) pairs the culling's thread drew itself (the pair list was full).
    pub pairs_in_place: u32,
}

impl FeatureStats for OmniRasterStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let r = self;
        let in_place = if r.in_place > 0 { format!(" ({} drawn in place: the large list was full)", r.in_place) } else { String::new() };
        let pairs_in_place = if r.pairs_in_place > 0 {
            format!(" ({} drawn by the culling: the pair list was full)", r.pairs_in_place)
        } else {
            String::new()
        };
        vec![(
            "shadow raster",
            format!(
                "{} (meshlet, face) pairs{pairs_in_place}; {} small triangles, {} large{in_place}; {} texels covered",
                r.pairs, r.small, r.large, r.texels
            ),
        )]
    }
}

/// The shadow atlas's plan of the last frame and its memory.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AtlasStats {
    /// Faces with a tile, and those drawn this frame (the others kept their texels).
    pub faces: usize,
    pub redrawn: usize,
    /// What every face's side was divided by to fit the budget (1: nothing).
    pub divided_by: u32,
    /// Bytes: the budget, all the atlas's buffers, the atlas itself, what its tiles use.
    pub budget: u64,
    pub shadow_bytes: u64,
    pub atlas_bytes: u64,
    pub tile_bytes: u64,
}

impl FeatureStats for AtlasStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let a = self;
        let mib = |b: u64| b as f64 / (1 << 20) as f64;
        let factor = if a.divided_by > 1 { format!("every face's side ÷{} to fit the budget", a.divided_by) } else { "full size".into() };
        vec![(
            "shadow atlas",
            format!(
                "{} faces ({} drawn, {} kept), {factor}; tiles {:.1} of the atlas's {:.1} MiB; all shadow buffers {:.1} of {:.0} MiB",
                a.faces,
                a.redrawn,
                a.faces - a.redrawn,
                mib(a.tile_bytes),
                mib(a.atlas_bytes),
                mib(a.shadow_bytes),
                mib(a.budget)
            ),
        )]
    }
}
