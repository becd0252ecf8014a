//! Point-light shadows drawn by compute shaders (`--omni-shadow compute`;
//! docs/DESIGN.md#compute-shadow-raster). The graphics modes are bound by filling 6 × size²
//! texels per light on the few SMs that run graphics work; here the whole GPU draws them. Each
//! frame: the lights' places and the counters are written and the depth buffer is cleared to
//! 1.0 (beyond reach); a thread per (meshlet instance, light) lists the faces the meshlet may
//! reach (omni_cull.comp); a work group per listed pair draws its small triangles, a thread
//! each, and lists the others (omni_raster.comp); a work group per listed large triangle draws
//! it (omni_raster_large.comp); the buffer is copied into the cube array the shading passes
//! sample, which ends as the graphics modes leave it.

use crate::descriptors::{FrameSets, Resource};
use crate::frame::FRAMES_IN_FLIGHT;
use crate::meshlet_scene::{storage_bytes, MeshletGeometry};
use crate::omni_shadow::NEAR_FRACTION;
use crate::pass::{FrameResources, Pass, Recording, SlotReport};
use crate::report::OmniRasterStats;
use crate::settings::OmniShadowSettings;
use gpu_allocator::MemoryLocation;
use ml_cpu::gpu_types::{OmniRasterCounters, OmniRasterPush};
use ml_cpu::meshlets::SceneMeshlets;
use ml_vk::commands::{copy_buffer_to_host, memory_barrier};
use ml_vk::image::aspect_transition;
use ml_vk::{shader, vk, Buffer, Context, VkError};

/// Work-group size of the culling.
const CULL_GROUP: u32 = 64;
/// Work groups a dispatch may have along x on every device (the shaders loop past it).
const MAX_GROUPS: u32 = 65535;
/// The largest triangle one thread draws (bounding box, texels a side); larger ones get a
/// work group each.
pub const SPLIT: u32 = 16;
/// The depth of a texel nothing reaches: 1.0's bits.
const FAR_BITS: u32 = 1.0f32.to_bits();

pub struct OmniShadowCompute {
    settings: OmniShadowSettings,
    geometry: MeshletGeometry,
    /// This frame's shadowed lights (vec4 each: position, radius), written by the command
    /// buffer itself (vkCmdUpdateBuffer), so frames in flight each see their own.
    lights: Buffer,
    counters: Buffer,
    /// The counters, copied out at the end of the pass, per frame slot.
    readback: Vec<Buffer>,
    pairs: Buffer,
    large: Buffer,
    /// 32-bit depths, layer after layer as the cube array holds them.
    depths: Buffer,
    pair_capacity: u32,
    /// Large triangles the list holds; past it, the thread that found one draws it (slowly,
    /// but nothing is lost; the table reports how many).
    large_capacity: u32,
    sets: FrameSets,
    layout: vk::PipelineLayout,
    pipelines: [vk::Pipeline; 3],
}

impl OmniShadowCompute {
    pub fn new(
        ctx: &Context,
        scene: &ml_cpu::scene::Scene,
        (settings, large_capacity): (OmniShadowSettings, u32),
    ) -> Result<OmniShadowCompute, VkError> {
        let geometry = SceneMeshlets::build(scene).map_err(|e| VkError::Limit(e.to_string()))?;
        let shaders = [&ml_shaders::OMNI_CULL_COMP, &ml_shaders::OMNI_RASTER_COMP, &ml_shaders::OMNI_RASTER_LARGE_COMP];
        let stages = shaders.map(|s| (s, vk::ShaderStageFlags::COMPUTE));
        // Six faces per meshlet instance and light at most: the pair list cannot overflow.
        let pairs = geometry.meshlet_instances.len() as u64 * settings.lights as u64 * 6;
        let pair_capacity = u32::try_from(pairs.max(1)).map_err(|_| VkError::Limit(format!("{pairs} shadow (meshlet, face) pairs")))?;
        let pass = OmniShadowCompute {
            settings,
            geometry: MeshletGeometry::upload(ctx, &geometry)?,
            lights: Buffer::null(),
            counters: Buffer::null(),
            readback: Vec::new(),
            pairs: Buffer::null(),
            large: Buffer::null(),
            depths: Buffer::null(),
            pair_capacity,
            large_capacity,
            sets: FrameSets::empty(),
            layout: vk::PipelineLayout::null(),
            pipelines: [vk::Pipeline::null(); 3],
        };
        ml_vk::build(ctx, pass, |p| {
            use vk::BufferUsageFlags as U;
            let gpu = MemoryLocation::GpuOnly;
            let storage = U::STORAGE_BUFFER;
            p.lights = Buffer::new(ctx, "shadowed lights", settings.lights as u64 * 16, storage | U::TRANSFER_DST, gpu)?;
            let counter_bytes = size_of::<OmniRasterCounters>() as u64;
            let counter_usage = storage | U::INDIRECT_BUFFER | U::TRANSFER_DST | U::TRANSFER_SRC;
            p.counters = Buffer::new(ctx, "shadow raster counters", counter_bytes, counter_usage, gpu)?;
            for _ in 0..FRAMES_IN_FLIGHT {
                let readback =
                    Buffer::new(ctx, "shadow raster counters read-back", counter_bytes, U::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
                p.readback.push(readback);
            }
            let pair_bytes = storage_bytes(ctx, "shadow (meshlet, face) pairs", p.pair_capacity as u64 * 8)?;
            p.pairs = Buffer::new(ctx, "shadow pairs", pair_bytes, storage, gpu)?;
            p.large = Buffer::new(
                ctx,
                "shadow large triangles",
                storage_bytes(ctx, "shadow large triangles", large_capacity.max(1) as u64 * 8)?,
                storage,
                gpu,
            )?;
            let depth_bytes = storage_bytes(ctx, "shadow cube depths", settings.bytes())?;
            p.depths = Buffer::new(ctx, "shadow cube depths", depth_bytes, storage | U::TRANSFER_SRC | U::TRANSFER_DST, gpu)?;
            p.sets = FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?;
            let push =
                [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::COMPUTE).size(size_of::<OmniRasterPush>() as u32)];
            p.layout = shader::pipeline_layout(ctx, &[p.sets.layout.raw], &push)?;
            for (pipeline, s) in p.pipelines.iter_mut().zip(shaders) {
                *pipeline = shader::compute_pipeline(ctx, s.spirv, p.layout, &[])?;
            }
            Ok(())
        })
    }

    fn push(&self) -> OmniRasterPush {
        let projection = glam::Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, NEAR_FRACTION, 1.0);
        OmniRasterPush {
            projection: projection.to_cols_array_2d(),
            sizes: [self.settings.size, self.settings.lights, SPLIT, self.geometry.meshlet_instance_count],
            capacity: [self.pair_capacity, self.large_capacity, 0, 0],
        }
    }
}

impl Pass for OmniShadowCompute {
    fn timer_name(&self) -> Option<&'static str> {
        Some("omni shadows")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let own = |name: &str| {
            let buffer = match name {
                "ShadowLightBuffer" => &self.lights,
                "OmniRasterCounterBuffer" => &self.counters,
                "OmniPairBuffer" => &self.pairs,
                "OmniLargeBuffer" => &self.large,
                "CubeDepthBuffer" => &self.depths,
                _ => return None,
            };
            Some(Resource::Buffer(buffer.raw))
        };
        self.sets.write(ctx, frame.slot, &|name| own(name).or_else(|| self.geometry.buffer(name)).or_else(|| frame.buffer(name)))
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let d = &ctx.device;
        let lights: Vec<[f32; 4]> =
            rec.shadowed.iter().take(self.settings.lights as usize).map(|l| l.position.extend(l.radius).to_array()).collect();
        if lights.is_empty() {
            return;
        }
        let cubes = &rec.scene.omni.cubes;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let indirect = vk::PipelineStageFlags::DRAW_INDIRECT;
        let readers = vk::PipelineStageFlags::FRAGMENT_SHADER | compute;
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let start = OmniRasterCounters { pairs: [0, 1, 1, 0], large: [0, 1, 1, 0], drawn: [0; 4] };
        let push = self.push();
        let depth = vk::ImageAspectFlags::DEPTH;
        // SAFETY: recording state outside a render pass; every buffer and pipeline lives as
        // long as this pass, the cubes as long as the scene, both beyond the frames in flight.
        unsafe {
            // The last frame's passes read and wrote these buffers (and its copy read them).
            memory_barrier(
                ctx,
                cmd,
                (compute | indirect | transfer, rw | vk::AccessFlags::TRANSFER_READ),
                (transfer, vk::AccessFlags::TRANSFER_WRITE),
            );
            d.cmd_update_buffer(cmd, self.lights.raw, 0, bytemuck::cast_slice(&lights));
            d.cmd_update_buffer(cmd, self.counters.raw, 0, bytemuck::bytes_of(&start));
            d.cmd_fill_buffer(cmd, self.depths.raw, 0, vk::WHOLE_SIZE, FAR_BITS);
            memory_barrier(ctx, cmd, (transfer, vk::AccessFlags::TRANSFER_WRITE), (compute, rw));
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[self.sets.sets[rec.slot]], &[]);
            d.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[0]);
            let groups = self.geometry.meshlet_instance_count.div_ceil(CULL_GROUP).clamp(1, MAX_GROUPS);
            d.cmd_dispatch(cmd, groups, lights.len() as u32, 1);
            let listed = (compute | indirect, rw | vk::AccessFlags::INDIRECT_COMMAND_READ);
            memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), listed);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[1]);
            d.cmd_dispatch_indirect(cmd, self.counters.raw, std::mem::offset_of!(OmniRasterCounters, pairs) as u64);
            memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), listed);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[2]);
            d.cmd_dispatch_indirect(cmd, self.counters.raw, std::mem::offset_of!(OmniRasterCounters, large) as u64);
            memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (transfer, vk::AccessFlags::TRANSFER_READ));
            // Whatever the last frame's shading read is overwritten whole.
            let dst = (transfer, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
            aspect_transition(ctx, cmd, (cubes.raw, depth), (readers, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED), dst);
            let size = self.settings.size;
            let layers = vk::ImageSubresourceLayers::default().aspect_mask(depth).base_array_layer(0).layer_count(self.settings.lights * 6);
            let region = [vk::BufferImageCopy::default().image_subresource(layers).image_extent(vk::Extent3D {
                width: size,
                height: size,
                depth: 1,
            })];
            d.cmd_copy_buffer_to_image(cmd, self.depths.raw, cubes.raw, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &region);
            let sampled = (readers, vk::AccessFlags::SHADER_READ, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
            aspect_transition(ctx, cmd, (cubes.raw, depth), dst, sampled);
        }
        let counter_bytes = size_of::<OmniRasterCounters>() as u64;
        copy_buffer_to_host(ctx, cmd, (self.counters.raw, self.readback[rec.slot].raw), counter_bytes);
    }

    fn collect(&self, slot: usize, report: &mut SlotReport) {
        let c: OmniRasterCounters = bytemuck::pod_read_unaligned(&self.readback[slot].mapped()[..size_of::<OmniRasterCounters>()]);
        report.omni_raster = Some(OmniRasterStats {
            pairs: c.pairs[3],
            small: c.drawn[0].saturating_sub(c.drawn[1]),
            large: c.large[3],
            in_place: c.drawn[1],
            texels: c.drawn[2],
        });
    }

    fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            for p in self.pipelines {
                ctx.device.destroy_pipeline(p, None);
            }
            ctx.device.destroy_pipeline_layout(self.layout, None);
        }
        self.pipelines = [vk::Pipeline::null(); 3];
        self.layout = vk::PipelineLayout::null();
        self.sets.destroy(ctx);
        for b in [&mut self.lights, &mut self.counters, &mut self.pairs, &mut self.large, &mut self.depths] {
            b.destroy(ctx);
        }
        for b in &mut self.readback {
            b.destroy(ctx);
        }
        self.readback.clear();
        self.geometry.destroy(ctx);
    }
}

impl ml_vk::Release for OmniShadowCompute {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
