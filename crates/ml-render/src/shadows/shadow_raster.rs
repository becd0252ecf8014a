//! The compute shadow raster (docs/DESIGN.md#compute-shadow-raster): depth-only views drawn
//! by compute shaders into a buffer of 32-bit depths, copied into the depth image the shading
//! passes sample. The views are every shadowed light's six cube faces (the point-light pass,
//! passes/omni_shadow_compute.rs, each frame) or one orthographic view (the sun's shadow map,
//! sun_shadow.rs, once). Per drawing: the lights' places and the counters are written and the
//! depths cleared to 1.0 (beyond reach); a thread per (meshlet instance, light) lists the
//! views the meshlet may reach (omni_cull.comp); a work group per listed pair draws its small
//! triangles, a thread each, and lists the others (omni_raster.comp); a work group per listed
//! large triangle draws it (omni_raster_large.comp); the buffer is copied into the image.

use crate::descriptors::{FrameSets, Resource};
use crate::error::RenderError;
use crate::scene::meshlets::{storage_bytes, MeshletGeometryView};
use crate::specialization::compute_pipeline;
use gpu_allocator::MemoryLocation;
use ml_cpu::gpu_types::{OmniRasterCounters, OmniRasterPush, ShadowCubeTiles};
use ml_vk::commands::{memory_barrier, update_buffer};
use ml_vk::image::aspect_transition;
use ml_vk::{shader, vk, Buffer, Context, VkError};

/// Work groups a dispatch may have along x on every device (the shaders loop past it).
const MAX_GROUPS: u32 = 65535;
/// The largest triangle one thread draws (bounding box, texels a side); larger ones get a
/// work group each.
pub const SPLIT: u32 = 16;
const COMPUTE: vk::PipelineStageFlags = vk::PipelineStageFlags::COMPUTE_SHADER;
const RW: vk::AccessFlags = vk::AccessFlags::from_raw(vk::AccessFlags::SHADER_READ.as_raw() | vk::AccessFlags::SHADER_WRITE.as_raw());
/// The depth of a texel nothing reaches: 1.0's bits.
const FAR_BITS: u32 = 1.0f32.to_bits();
/// Work groups that clear each face of the atlas (shadow_atlas_clear.comp's SLICES).
const CLEAR_SLICES: u32 = 16;

/// What one drawing covers.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowViews {
    /// Six cube faces (90° perspective, in the light's frame in radii) for each of `lights`.
    Cubes { lights: u32 },
    /// One orthographic view (world space, the projection is its view-projection).
    Ortho,
    /// Six cube faces for each of `lights`, the ones the tile table says, into the shadow
    /// atlas's `depths` (ShadowAtlasGpu); the pair list holds `pairs`.
    Atlas { lights: u32, pairs: u32, depths: vk::Buffer, tiles: vk::Buffer },
}

impl ShadowViews {
    /// Lights (each a cube, or the one view) and the image layers they fill.
    pub fn lights(self) -> u32 {
        match self {
            ShadowViews::Cubes { lights } | ShadowViews::Atlas { lights, .. } => lights,
            ShadowViews::Ortho => 1,
        }
    }

    fn layers(self) -> u32 {
        match self {
            ShadowViews::Cubes { lights } | ShadowViews::Atlas { lights, .. } => lights * 6,
            ShadowViews::Ortho => 1,
        }
    }
}

/// Where the depths go: a D32_SFLOAT image whose first layers the views fill by a copy.
pub struct ShadowTarget {
    pub image: vk::Image,
    /// Drawn outside the frames (the sun's map, once): the stages that read it after, for
    /// which the drawing transitions it by hand (from undefined to
    /// DEPTH_STENCIL_READ_ONLY_OPTIMAL). None: a frame's pass, whose declared use took it in
    /// TRANSFER_DST_OPTIMAL and which leaves it so (`sync` orders it for the readers).
    pub readers: Option<vk::PipelineStageFlags>,
}

pub struct ShadowRaster {
    views: ShadowViews,
    size: u32,
    /// The scene's meshlets (SceneGpu's).
    geometry: MeshletGeometryView,
    /// The drawing's lights (vec4 each: position, radius), written by the command buffer
    /// itself (vkCmdUpdateBuffer), so frames in flight each see their own.
    lights: Buffer,
    pub counters: Buffer,
    pairs: Buffer,
    large: Buffer,
    /// 32-bit depths, layer after layer as the image holds them, row by row (the atlas: a
    /// stand-in; it draws into the atlas's buffer).
    depths: Buffer,
    /// A stand-in for the atlas's tile table (cubes and the orthographic view).
    tiles: Buffer,
    /// The atlas: the lights with faces drawn this frame, written by the command buffer (a
    /// stand-in otherwise).
    redrawn: Buffer,
    pair_capacity: u32,
    /// Large triangles the list holds; past it, the thread that found one draws it (slowly,
    /// but nothing is lost; the table reports how many).
    large_capacity: u32,
    sets: FrameSets,
    layout: vk::PipelineLayout,
    /// Culling, small triangles, large triangles; the atlas's clear.
    pipelines: [vk::Pipeline; 4],
}

impl ShadowRaster {
    /// The raster of the scene's meshlets `geometry` into `views` of `size`² texels, with
    /// `slots` descriptor sets (one per frame in flight).
    pub fn new(
        ctx: &Context,
        geometry: MeshletGeometryView,
        (views, size, large_capacity): (ShadowViews, u32, u32),
        slots: usize,
    ) -> Result<ShadowRaster, RenderError> {
        let shaders = [
            &ml_shaders::OMNI_CULL_COMP,
            &ml_shaders::OMNI_RASTER_COMP,
            &ml_shaders::OMNI_RASTER_LARGE_COMP,
            &ml_shaders::SHADOW_ATLAS_CLEAR_COMP,
        ];
        let stages = shaders.map(|s| (s, vk::ShaderStageFlags::COMPUTE));
        // Cubes: six views per meshlet instance and light at most, the pair list cannot
        // overflow; the atlas's is a share of its budget.
        let pairs = geometry.meshlet_instance_count as u64 * views.layers() as u64;
        let pairs = match views {
            ShadowViews::Atlas { pairs: capacity, .. } => pairs.min(capacity as u64),
            _ => pairs,
        };
        let pair_capacity = u32::try_from(pairs.max(1))
            .map_err(|_| RenderError::Invalid(format!("{pairs} shadow (meshlet, face) pairs are more than one list holds")))?;
        let raster = ShadowRaster {
            views,
            size,
            geometry,
            lights: Buffer::null(),
            counters: Buffer::null(),
            pairs: Buffer::null(),
            large: Buffer::null(),
            depths: Buffer::null(),
            tiles: Buffer::null(),
            redrawn: Buffer::null(),
            pair_capacity,
            large_capacity,
            sets: FrameSets::empty(),
            layout: vk::PipelineLayout::null(),
            pipelines: [vk::Pipeline::null(); 4],
        };
        ml_vk::build(ctx, raster, |r| {
            use vk::BufferUsageFlags as U;
            let gpu = MemoryLocation::GpuOnly;
            let storage = U::STORAGE_BUFFER;
            r.lights = Buffer::new(ctx, "shadowed lights", views.lights() as u64 * 16, storage | U::TRANSFER_DST, gpu)?;
            let counter_bytes = size_of::<OmniRasterCounters>() as u64;
            let counter_usage = storage | U::INDIRECT_BUFFER | U::TRANSFER_DST | U::TRANSFER_SRC;
            r.counters = Buffer::new(ctx, "shadow raster counters", counter_bytes, counter_usage, gpu)?;
            let pair_bytes = storage_bytes(ctx, "shadow (meshlet, face) pairs", r.pair_capacity as u64 * 8)?;
            r.pairs = Buffer::new(ctx, "shadow pairs", pair_bytes, storage, gpu)?;
            r.large = Buffer::new(
                ctx,
                "shadow large triangles",
                storage_bytes(ctx, "shadow large triangles", large_capacity.max(1) as u64 * 8)?,
                storage,
                gpu,
            )?;
            let atlas = matches!(views, ShadowViews::Atlas { .. });
            let texels = if atlas { 1 } else { views.layers() as u64 * size as u64 * size as u64 };
            let depth_bytes = storage_bytes(ctx, "shadow depths", texels * 4)?;
            r.depths = Buffer::new(ctx, "shadow depths", depth_bytes, storage | U::TRANSFER_SRC | U::TRANSFER_DST, gpu)?;
            let tile_bytes = size_of::<ml_cpu::gpu_types::ShadowCubeTiles>() as u64;
            r.tiles = Buffer::new(ctx, "shadow tiles stand-in", tile_bytes, storage, gpu)?;
            let redrawn_bytes = if atlas { views.lights() as u64 * 4 } else { 4 };
            r.redrawn = Buffer::new(ctx, "redrawn shadowed lights", redrawn_bytes, storage | U::TRANSFER_DST, gpu)?;
            r.sets = FrameSets::new(ctx, &stages, 0, slots)?;
            let push =
                [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::COMPUTE).size(size_of::<OmniRasterPush>() as u32)];
            r.layout = shader::pipeline_layout(ctx, &[r.sets.layout.raw], &push)?;
            // Every step includes shadows/omni_raster.glsl, which declares them all.
            let [surface, mask] = r.geometry.surface_constants();
            let spec = [("ORTHO_VIEW", u32::from(views == ShadowViews::Ortho)), ("ATLAS", u32::from(atlas)), surface, mask];
            // The clear is the atlas's alone.
            let used = if atlas { 4 } else { 3 };
            for (pipeline, s) in r.pipelines.iter_mut().zip(shaders).take(used) {
                *pipeline = compute_pipeline(ctx, s, r.layout, &spec)?;
            }
            Ok(())
        })
    }

    /// Point slot `slot`'s set at the raster's own buffers and the scene's meshlets; `objects`,
    /// `alpha_masks`: the scene's object and alpha-mask buffers.
    pub fn bind(&mut self, ctx: &Context, slot: usize, (objects, alpha_masks): (vk::Buffer, vk::Buffer)) -> Result<(), VkError> {
        let (depths, tiles) = match self.views {
            ShadowViews::Atlas { depths, tiles, .. } => (depths, tiles),
            _ => (self.depths.raw, self.tiles.raw),
        };
        let own = |name: &str| {
            let buffer = match name {
                "ShadowLightBuffer" => self.lights.raw,
                "OmniRasterCounterBuffer" => self.counters.raw,
                "OmniPairBuffer" => self.pairs.raw,
                "OmniLargeBuffer" => self.large.raw,
                "CubeDepthBuffer" => depths,
                "ShadowTileBuffer" => tiles,
                "ShadowRedrawBuffer" => self.redrawn.raw,
                "ObjectBuffer" => objects,
                "AlphaMaskBuffer" => alpha_masks,
                _ => return None,
            };
            Some(Resource::Buffer(buffer))
        };
        self.sets.write(ctx, slot, &|name| own(name).or_else(|| self.geometry.buffer(name)))
    }

    /// Record one drawing with slot `slot`'s set: `lights` (cubes: one per cube, at most the
    /// views' lights; the orthographic view: one, at the origin with radius 1) seen through
    /// `projection` (omni_raster.glsl), into `target`. Layers of no light stay 1.0.
    pub fn record(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: usize,
        lights: &[[f32; 4]],
        projection: glam::Mat4,
        target: &ShadowTarget,
    ) {
        let d = &ctx.device;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        // The last drawing's copy read the depths.
        self.start(ctx, cmd, lights);
        // SAFETY: recording state outside a render pass; the buffer lives as long as this raster.
        unsafe { d.cmd_fill_buffer(cmd, self.depths.raw, 0, vk::WHOLE_SIZE, FAR_BITS) };
        memory_barrier(ctx, cmd, (transfer, vk::AccessFlags::TRANSFER_WRITE), (COMPUTE, RW));
        self.draw(ctx, cmd, slot, lights.len() as u32, projection);
        memory_barrier(ctx, cmd, (COMPUTE, vk::AccessFlags::SHADER_WRITE), (transfer, vk::AccessFlags::TRANSFER_READ));
        let depth = vk::ImageAspectFlags::DEPTH;
        // SAFETY: recording state outside a render pass; the target lives as long as its
        // owner, beyond the submission.
        unsafe {
            let dst = (transfer, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
            let image = (target.image, depth);
            if let Some(readers) = target.readers {
                aspect_transition(ctx, cmd, image, (readers, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED), dst);
            }
            let layers = vk::ImageSubresourceLayers::default().aspect_mask(depth).base_array_layer(0).layer_count(self.views.layers());
            let extent = vk::Extent3D { width: self.size, height: self.size, depth: 1 };
            let region = [vk::BufferImageCopy::default().image_subresource(layers).image_extent(extent)];
            d.cmd_copy_buffer_to_image(cmd, self.depths.raw, target.image, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &region);
            if let Some(readers) = target.readers {
                let sampled = (readers, vk::AccessFlags::SHADER_READ, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
                aspect_transition(ctx, cmd, image, dst, sampled);
            }
        }
    }

    /// Record one frame of the shadow atlas with slot `slot`'s set: `lights` (light i: the
    /// faces `tiles[i]` names) seen through `projection` (every face's). The faces it redraws
    /// are cleared and drawn; the others keep their texels, and lights with none to redraw
    /// cost nothing: the clear and the culling run over the others alone (a frame that keeps
    /// every face writes the table and nothing else). The table (by transfers) and the
    /// atlas (by compute shaders) as the pass declares them (`sync` orders them after the
    /// last shading and for the next); ends with the counters' writes visible to transfers.
    pub fn record_atlas(
        &self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        slot: usize,
        (lights, tiles): (&[[f32; 4]], &[ShadowCubeTiles]),
        projection: glam::Mat4,
    ) {
        let ShadowViews::Atlas { tiles: table, .. } = self.views else { return };
        let d = &ctx.device;
        let redrawn: Vec<u32> = (0..tiles.len() as u32).filter(|&i| tiles[i as usize].redraw != 0).collect();
        self.start(ctx, cmd, lights);
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let written = (transfer, vk::AccessFlags::TRANSFER_WRITE);
        // The counters are copied out.
        let after = (transfer, vk::AccessFlags::TRANSFER_READ);
        update_buffer(ctx, cmd, table, bytemuck::cast_slice(tiles));
        if redrawn.is_empty() {
            memory_barrier(ctx, cmd, written, after);
            return;
        }
        update_buffer(ctx, cmd, self.redrawn.raw, bytemuck::cast_slice(&redrawn));
        memory_barrier(ctx, cmd, written, (COMPUTE, RW));
        // SAFETY: recording state outside a render pass; every buffer and pipeline lives as
        // long as this raster and the atlas, beyond the submission.
        unsafe {
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[self.sets.sets[slot]], &[]);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[3]);
            d.cmd_dispatch(cmd, redrawn.len() as u32, 6, CLEAR_SLICES);
            // The culling's thread may draw (a full pair list) into what the clear cleared.
            memory_barrier(ctx, cmd, (COMPUTE, vk::AccessFlags::SHADER_WRITE), (COMPUTE, RW));
        }
        self.draw(ctx, cmd, slot, redrawn.len() as u32, projection);
        memory_barrier(ctx, cmd, (COMPUTE, vk::AccessFlags::SHADER_WRITE), after);
    }

    /// The start of a drawing: after the last drawing's passes, the lights and the counters
    /// written.
    fn start(&self, ctx: &Context, cmd: vk::CommandBuffer, lights: &[[f32; 4]]) {
        let start = OmniRasterCounters { pairs: [0, 1, 1, 0], large: [0, 1, 1, 0], drawn: [0; 4] };
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let before = (COMPUTE | vk::PipelineStageFlags::DRAW_INDIRECT | transfer, RW | vk::AccessFlags::TRANSFER_READ);
        memory_barrier(ctx, cmd, before, (transfer | COMPUTE, vk::AccessFlags::TRANSFER_WRITE | RW));
        update_buffer(ctx, cmd, self.lights.raw, bytemuck::cast_slice(lights));
        update_buffer(ctx, cmd, self.counters.raw, bytemuck::bytes_of(&start));
    }

    /// The culling and both rasters of `lights` lights (the atlas: of the first `lights` the
    /// redrawn list names), their inputs written and visible.
    fn draw(&self, ctx: &Context, cmd: vk::CommandBuffer, slot: usize, lights: u32, projection: glam::Mat4) {
        let d = &ctx.device;
        let push = OmniRasterPush {
            projection: projection.to_cols_array_2d(),
            sizes: [self.size, self.views.lights(), SPLIT, self.geometry.meshlet_instance_count],
            capacity: [self.pair_capacity, self.large_capacity, 0, 0],
        };
        let listed = (COMPUTE | vk::PipelineStageFlags::DRAW_INDIRECT, RW | vk::AccessFlags::INDIRECT_COMMAND_READ);
        // SAFETY: recording state outside a render pass; every buffer and pipeline lives as
        // long as this raster, beyond the submission.
        unsafe {
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[self.sets.sets[slot]], &[]);
            d.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[0]);
            let [groups, ..] = ml_shaders::OMNI_CULL_COMP.groups([self.geometry.meshlet_instance_count, 1, 1]);
            let groups = groups.clamp(1, MAX_GROUPS);
            d.cmd_dispatch(cmd, groups, lights, 1);
            memory_barrier(ctx, cmd, (COMPUTE, vk::AccessFlags::SHADER_WRITE), listed);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[1]);
            d.cmd_dispatch_indirect(cmd, self.counters.raw, std::mem::offset_of!(OmniRasterCounters, pairs) as u64);
            memory_barrier(ctx, cmd, (COMPUTE, vk::AccessFlags::SHADER_WRITE), listed);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[2]);
            d.cmd_dispatch_indirect(cmd, self.counters.raw, std::mem::offset_of!(OmniRasterCounters, large) as u64);
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for p in self.pipelines {
            ml_vk::shader::release_pipeline(ctx, p);
        }
        self.pipelines = [vk::Pipeline::null(); 4];
        self.layout = vk::PipelineLayout::null();
        self.sets.destroy(ctx);
        for b in
            [&mut self.lights, &mut self.counters, &mut self.pairs, &mut self.large, &mut self.depths, &mut self.tiles, &mut self.redrawn]
        {
            b.destroy(ctx);
        }
    }
}

impl ml_vk::Release for ShadowRaster {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
