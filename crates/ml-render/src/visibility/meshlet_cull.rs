//! GPU culling of the visibility technique (docs/DESIGN.md#gpu-culling), in two phases, no
//! CPU work per object. Early: the counters cleared, every instance tested against the frustum
//! (instance_cull.comp), then a work group per surviving instance tests its meshlets that were
//! visible last frame against the frustum and their back-face cones (meshlet_cull.comp) and
//! gives each survivor a draw slot; a work group per slot then tests its triangles
//! (triangle_cull.comp) and appends the survivors to the compacted index buffer and the
//! phase's indexed draw. Late (after the early raster and the depth pyramid): every meshlet of
//! those instances again, now also against the pyramid; the newly visible are drawn the same
//! way, and every meshlet's visibility is kept for the next frame. The late pass copies the
//! counters out for the report. With the compute raster, step 3 is triangle_raster.comp: the
//! same tests, then the small triangles rasterised there and the others listed by bins for
//! the large-triangle pass (which then reads the counters back instead) or, with the hybrid
//! raster, appended to the draw; the early phase clears its 64-bit buffer first.

use crate::antialiasing::Antialiasing;
use crate::descriptors::FrameSets;
use crate::error::RenderError;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{FrameWork, Pass, Prepare, Recording, SlotReport};
use crate::plan::Phase;
use crate::read_back::HostRead;
use crate::report::{FeatureStats, FrameStats};
use crate::specialization::{compute_pipeline, Constant};
use crate::sync::{Use, DEPTH_PYRAMID, MESHLET_VISIBILITY, VISIBILITY_DEPTH};
use crate::targets::depth_pyramid_shape;
use crate::technique::{LargeTriangles, Raster};
use crate::visibility::meshlet_scene::{
    MeshletScene, SharedMeshletScene, COMPACTED_INDICES, CULL_COUNTERS, DRAW_SLOTS, LARGE_BINS, LARGE_TRIANGLES, LAYER_CANDIDATES,
    TRIANGLE_IDS, VISIBLE_INSTANCES,
};
use ml_cpu::gpu_types::{CullCounters, CullPush};
use ml_vk::commands::memory_barrier;
use ml_vk::{shader, vk, Context, VkError};

pub struct MeshletCull {
    phase: Phase,
    culling: bool,
    raster: Raster,
    scene: SharedMeshletScene,
    sets: FrameSets,
    pipeline_layout: vk::PipelineLayout,
    /// The instance test (early phase only; null in the late one).
    instance_pipeline: vk::Pipeline,
    meshlet_pipeline: vk::Pipeline,
    triangle_pipeline: vk::Pipeline,
}

impl MeshletCull {
    /// `layers`: the transparent objects are blended in layers, not drawn into the buffer —
    /// but for their cores where `cores` (Shading::cores_constant) says so, whose pixels the
    /// compute raster lists for the layers' build where `candidates`.
    pub fn new(
        ctx: &Context,
        scene: SharedMeshletScene,
        phase: Phase,
        (culling, raster, (layers, cores, candidates), antialiasing): (bool, Raster, (bool, Option<Constant>, bool), Antialiasing),
    ) -> Result<MeshletCull, VkError> {
        let compute = vk::ShaderStageFlags::COMPUTE;
        // Scenes with masked objects get the compute raster that draws their pixels from
        // shared memory (its shared memory would cost the others occupancy).
        let triangles = match raster {
            Raster::Hardware => &ml_shaders::TRIANGLE_CULL_COMP,
            Raster::Compute { .. } if scene.borrow().geometry.mask_tests => &ml_shaders::TRIANGLE_RASTER_MASKED_COMP,
            Raster::Compute { .. } => &ml_shaders::TRIANGLE_RASTER_COMP,
        };
        let stages = [(&ml_shaders::INSTANCE_CULL_COMP, compute), (&ml_shaders::MESHLET_CULL_COMP, compute), (triangles, compute)];
        let pass = MeshletCull {
            phase,
            culling,
            raster,
            scene,
            sets: FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?,
            pipeline_layout: vk::PipelineLayout::null(),
            instance_pipeline: vk::Pipeline::null(),
            meshlet_pipeline: vk::Pipeline::null(),
            triangle_pipeline: vk::Pipeline::null(),
        };
        ml_vk::build(ctx, pass, |p| {
            let push = [vk::PushConstantRange::default().stage_flags(compute).size(std::mem::size_of::<CullPush>() as u32)];
            p.pipeline_layout = shader::pipeline_layout(ctx, &[p.sets.layout.raw], &push)?;
            if phase == Phase::Early {
                let skip: Vec<_> = [("SKIP_BLENDED", u32::from(layers))].into_iter().chain(cores).collect();
                p.instance_pipeline = compute_pipeline(ctx, &ml_shaders::INSTANCE_CULL_COMP, p.pipeline_layout, &skip)?;
            }
            p.meshlet_pipeline = compute_pipeline(ctx, &ml_shaders::MESHLET_CULL_COMP, p.pipeline_layout, &[])?;
            // Only the compute raster's triangle pass draws, so only it tests surfaces: the
            // hardware raster's culling (triangle_cull.comp) declares no SURFACE_TESTS, only the
            // samples a triangle may cover.
            let constants = match raster {
                Raster::Hardware => vec![antialiasing.constant()],
                Raster::Compute { .. } => {
                    let [tests, masks] = p.scene.borrow().geometry.surface_constants();
                    let listing = candidates.then_some(("LAYER_CANDIDATES", 1));
                    [tests, masks, antialiasing.constant()].into_iter().chain(cores).chain(listing).collect()
                }
            };
            p.triangle_pipeline = compute_pipeline(ctx, triangles, p.pipeline_layout, &constants)?;
            Ok(())
        })
    }
}

/// The culling passes' push constants for frame slot `slot` (the large-triangle pass reads
/// the same).
pub fn cull_push(phase: Phase, culling: bool, raster: Raster, (scene, slot): (&MeshletScene, usize), extent: vk::Extent2D) -> CullPush {
    let (_, levels) = depth_pyramid_shape(extent);
    let bins = raster.bin_list().is_some();
    CullPush {
        mode: [u32::from(phase == Phase::Late), u32::from(culling), levels, scene.capacity],
        triangles: [scene.geometry.triangles as u32, raster.split(), scene.frames[slot].large_capacity, u32::from(bins)],
    }
}

impl Pass for MeshletCull {
    fn timer_name(&self) -> Option<&'static str> {
        let compute = self.raster != Raster::Hardware;
        Some(match self.phase {
            Phase::Early if compute => "cull + compute raster (early)",
            Phase::Late if compute => "cull + compute raster (late)",
            Phase::Early => "cull (early)",
            Phase::Late => "cull (late)",
        })
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let scene = self.scene.borrow();
        self.sets.write(ctx, frame.slot, &|name| scene.buffer(frame, name))
    }

    /// The depth pyramid its shaders read (the late phase tests against it); the meshlet
    /// visibility; the culling's buffers of the slot, which it clears (early), fills,
    /// dispatches from and, where it reads the counters back, copies; the compute raster's
    /// lists and 64-bit buffer.
    fn uses(&self) -> Vec<Use> {
        use vk::AccessFlags as A;
        use vk::PipelineStageFlags as S;
        let rw = A::SHADER_READ | A::SHADER_WRITE;
        let compute = (S::COMPUTE_SHADER, rw);
        let early = self.phase == Phase::Early;
        let mut counters = (S::COMPUTE_SHADER | S::DRAW_INDIRECT, rw | A::INDIRECT_COMMAND_READ);
        if early {
            counters = (counters.0 | S::TRANSFER, counters.1 | A::TRANSFER_WRITE);
        }
        // The early phase reads which meshlets the last frame saw, the late one writes it.
        let visibility = if early { (S::COMPUTE_SHADER, A::SHADER_READ) } else { compute };
        let mut uses = vec![
            Use::buffer(DEPTH_PYRAMID, (S::COMPUTE_SHADER, A::SHADER_READ)),
            Use::buffer(MESHLET_VISIBILITY, visibility),
            Use::buffer(CULL_COUNTERS, counters),
            Use::buffer(VISIBLE_INSTANCES, compute),
            Use::buffer(DRAW_SLOTS, compute),
            Use::buffer(COMPACTED_INDICES, compute),
            Use::buffer(TRIANGLE_IDS, compute),
        ];
        if self.raster != Raster::Hardware {
            // Cleared by a transfer in the early phase.
            let depth = if early { (S::COMPUTE_SHADER | S::TRANSFER, rw | A::TRANSFER_WRITE) } else { compute };
            uses.push(Use::buffer(VISIBILITY_DEPTH, depth));
        }
        if self.raster.bin_list().is_some() {
            uses.extend([Use::buffer(LARGE_BINS, compute), Use::buffer(LARGE_TRIANGLES, compute)]);
        }
        if self.raster != Raster::Hardware {
            // The compute raster binds the layer candidates' list (writing it where it lists).
            uses.push(Use::buffer(LAYER_CANDIDATES, compute));
        }
        uses
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd, slot) = (rec.ctx, rec.cmd, rec.slot);
        let d = &ctx.device;
        let scene = self.scene.borrow();
        let f = &scene.frames[slot];
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let indirect = vk::PipelineStageFlags::DRAW_INDIRECT;
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let indirect_read = vk::AccessFlags::INDIRECT_COMMAND_READ;
        let push = cull_push(self.phase, self.culling, self.raster, (&scene, slot), rec.extent);
        let set = [self.sets.sets[slot]];
        // SAFETY: recording state outside a render pass; everything bound is alive until the
        // frame's fence signals.
        unsafe {
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layout, 0, &set, &[]);
            d.cmd_push_constants(cmd, self.pipeline_layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            if self.phase == Phase::Early {
                d.cmd_fill_buffer(cmd, f.counters.raw, 0, vk::WHOLE_SIZE, 0);
                if self.raster != Raster::Hardware {
                    // Nothing drawn: all ones, above every depth-and-id (the last frame's
                    // lighting on this slot read it).
                    d.cmd_fill_buffer(cmd, rec.targets.visibility_depth.raw, 0, vk::WHOLE_SIZE, u32::MAX);
                }
                memory_barrier(ctx, cmd, (transfer, vk::AccessFlags::TRANSFER_WRITE), (compute, rw));
                d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.instance_pipeline);
                let [groups, ..] = ml_shaders::INSTANCE_CULL_COMP.groups([scene.geometry.instance_count, 1, 1]);
                d.cmd_dispatch(cmd, groups.max(1), 1, 1);
                memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute | indirect, rw | indirect_read));
            }
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.meshlet_pipeline);
            d.cmd_dispatch_indirect(cmd, f.counters.raw, 0);
            // The triangle culling: a work group per draw slot of this phase.
            memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute | indirect, rw | indirect_read));
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.triangle_pipeline);
            let phase = usize::from(self.phase == Phase::Late);
            let meshlets = (std::mem::offset_of!(CullCounters, meshlets) + phase * 16) as u64;
            d.cmd_dispatch_indirect(cmd, f.counters.raw, meshlets);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.instance_pipeline);
        ml_vk::shader::release_pipeline(ctx, self.meshlet_pipeline);
        ml_vk::shader::release_pipeline(ctx, self.triangle_pipeline);
        self.instance_pipeline = vk::Pipeline::null();
        self.meshlet_pipeline = vk::Pipeline::null();
        self.triangle_pipeline = vk::Pipeline::null();
        self.pipeline_layout = vk::PipelineLayout::null();
        self.sets.destroy(ctx);
        self.scene.borrow_mut().destroy(ctx);
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for MeshletCull {
    /// The late phase (whose counters are read back): the slot's large-triangle lists grown
    /// where its last frame overflowed them.
    fn prepare(&mut self, prepare: &mut Prepare) -> Result<(), RenderError> {
        if self.phase == Phase::Late {
            let mut scene = self.scene.borrow_mut();
            let large = scene.grow_large_lists(prepare.ctx, prepare.slot)?;
            if large | scene.grow_candidates(prepare.ctx, prepare.slot)? {
                prepare.rebind = true;
            }
        }
        Ok(())
    }

    /// The late phase's counters, copied once the frame's every pass has added to them (the
    /// large triangles' pass adds the pixels it covered).
    fn host_reads(&self, slot: usize) -> Vec<HostRead> {
        if self.phase != Phase::Late {
            return Vec::new();
        }
        let scene = self.scene.borrow();
        vec![scene.readback.of(slot, CULL_COUNTERS, scene.frames[slot].counters.raw)]
    }

    /// Large triangles drawn in place where the lists will grow.
    fn redraws(&self, ctx: &Context, slot: usize) -> bool {
        self.phase == Phase::Late && self.scene.borrow().drew_in_place_for_want_of_room(ctx, slot)
    }

    fn collect(&self, slot: usize, _: &mut SlotReport, stats: &mut FrameStats) {
        if self.phase != Phase::Late {
            return;
        }
        let scene = self.scene.borrow();
        let c = scene.counters(slot);
        stats.set_feature(CullStats {
            raster: self.raster,
            instances: c.tested[2],
            visible_instances: c.dispatch[0],
            meshlet_instances: scene.capacity,
            early_tested: c.tested[0],
            early_drawn: c.meshlets[0][0],
            late_tested: c.tested[1],
            late_drawn: c.meshlets[1][0],
            meshlet_triangles: c.triangles[0] as u64 + c.triangles[1] as u64,
            triangles: [c.triangles[2], c.triangles[3], c.rasterized[0], c.rasterized[1], c.binned[2], c.binned[3]]
                .iter()
                .map(|&n| n as u64)
                .sum(),
            compute_triangles: c.rasterized[0] as u64 + c.rasterized[1] as u64,
            compute_pixels: c.rasterized[2] as u64,
            large_triangles: c.binned[2] as u64 + c.binned[3] as u64,
            bins: c.binned[0] as u64 + c.binned[1] as u64,
            in_place: c.rasterized[3] as u64,
            large_list: scene.frames[slot].large_capacity,
            scene_triangles: scene.geometry.triangles,
            layer_candidates: c.candidates[0] as u64,
            candidate_room: scene.frames[slot].candidate_capacity,
            cores_per_triangle: c.candidates[1] != 0,
        });
    }
}

impl ml_vk::Release for MeshletCull {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// What one frame's GPU culling tested and kept, and what its raster drew.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CullStats {
    /// The raster it drew with.
    pub raster: Raster,
    /// Instances (objects) tested, and those inside the frustum.
    pub instances: u32,
    pub visible_instances: u32,
    /// Meshlet instances of the scene (objects × meshlets of their meshes).
    pub meshlet_instances: u32,
    /// Early phase: meshlets visible last frame, tested; those drawn.
    pub early_tested: u32,
    pub early_drawn: u32,
    /// Late phase: every meshlet of the instances in the frustum, tested; those newly drawn.
    pub late_tested: u32,
    pub late_drawn: u32,
    /// Triangles of the meshlets drawn (both phases); of those, the triangles drawn (the rest
    /// culled one by one); the triangles of every object together.
    pub meshlet_triangles: u64,
    pub triangles: u64,
    pub scene_triangles: u64,
    /// Compute raster: of the triangles drawn, those it drew (the rest by the hardware), and
    /// the pixels they covered (hidden ones too); 0 with the hardware raster.
    pub compute_triangles: u64,
    pub compute_pixels: u64,
    /// Compute raster (large triangles in compute): the large triangles found, the 64×64
    /// bins of their boxes, and those drawn in place (the lists full).
    pub large_triangles: u64,
    pub bins: u64,
    pub in_place: u64,
    /// The lists' size in that frame (bins and large triangles each; they grow after a
    /// frame that overflowed them).
    pub large_list: u32,
    /// Compute raster with transparent objects' cores: the soft samples it listed for the
    /// layers (0: none listed), its list's room, and whether it left the cores to the
    /// per-triangle build (a core triangle it clipped or drew in place, or the list full: it
    /// grows).
    pub layer_candidates: u64,
    pub candidate_room: u32,
    pub cores_per_triangle: bool,
}

impl FeatureStats for CullStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let c = self;
        let share = 100.0 * c.triangles as f64 / c.scene_triangles.max(1) as f64;
        let mut rows = vec![
            ("instances", format!("{} submitted, {} in the frustum", c.instances, c.visible_instances)),
            (
                "meshlets",
                format!(
                    "{} in the scene; early: {} tested, {} drawn; late: {} tested, {} drawn",
                    c.meshlet_instances, c.early_tested, c.early_drawn, c.late_tested, c.late_drawn
                ),
            ),
            (
                "triangles",
                format!("{} drawn of {} ({share:.1} %); the meshlets drawn held {}", c.triangles, c.scene_triangles, c.meshlet_triangles),
            ),
        ];
        match c.raster {
            Raster::Hardware => {}
            Raster::Compute { large: LargeTriangles::Hardware, .. } => rows.push((
                "compute raster",
                format!(
                    "{} triangles ({} pixels covered), {} by the hardware",
                    c.compute_triangles,
                    c.compute_pixels,
                    c.triangles - c.compute_triangles
                ),
            )),
            Raster::Compute { large: LargeTriangles::Bins { .. }, .. } => {
                // Said only where it happened: a triangle is drawn in place when the bins'
                // lists are full (they grow for the slot's next frame).
                let in_place = if c.in_place > 0 {
                    format!(" ({} drawn in place: the bins' lists were full; they grow)", c.in_place)
                } else {
                    String::new()
                };
                rows.push((
                    "compute raster",
                    format!(
                        "{} small triangles a thread each, {} large ones in {} bins (lists of {}){in_place}; {} pixels covered",
                        c.compute_triangles, c.large_triangles, c.bins, c.large_list, c.compute_pixels
                    ),
                ))
            }
        }
        if c.layer_candidates > 0 || c.cores_per_triangle {
            let built = if c.cores_per_triangle {
                if c.layer_candidates > u64::from(c.candidate_room) {
                    "; the list was full (it grows): the cores built a thread per triangle"
                } else {
                    "; a core triangle it clipped (or drew in place): the cores built a thread per triangle"
                }
            } else {
                ""
            };
            rows.push((
                "layer candidates",
                format!(
                    "{} soft samples of transparent cores listed for the layers (room for {}){built}",
                    c.layer_candidates, c.candidate_room
                ),
            ));
        }
        rows
    }
}
