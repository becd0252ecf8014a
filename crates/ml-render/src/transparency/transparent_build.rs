//! The transparent layers' build: each fragment of a transparent object in front of the opaque
//! depth appended to its pixel's list (layers.glsl), in compute (the H100 runs fragment
//! shaders on 4 of its 132 SMs). Objects of few triangles (panes, cards) are rasterised over
//! the tiles their screen rectangles meet (transparent_build_compute.glsl); the others a
//! thread per triangle (transparent_build_triangles.glsl), which lists its triangles too
//! large for a thread for a work group each (transparent_build_large.glsl) and the huge ones
//! for the tiles' build. Runs after the opaque raster, before the resolve; clears the slot's
//! lists first. Where the compute raster lists the soft samples of transparent objects' cores
//! as candidates (no anti-aliasing; `TransparencySettings::candidate_list`), a fourth build
//! makes their nodes (transparent_build_candidates.glsl), and the per-triangle build takes the
//! cores only in a frame whose raster could not list them all.

use super::{node_bytes, LayerBuffers, TransparencySettings, TransparencyStats, LAYER_BUFFERS};
use crate::compute_pass::ComputePass;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::{FrameResources, FRAMES_IN_FLIGHT};
use crate::gpu_mesh::{layer_mesh, SceneMeshes};
use crate::pass::{FrameWork, Pass, Recording, SlotReport};
use crate::read_back::HostRead;
use crate::report::FrameStats;
use crate::scene::SceneGpu;
use crate::shading::Shading;
use crate::sync::{BufferName, Use, CULL_COUNTERS, DEPTH_PYRAMID, LAYER_CANDIDATES, LIGHT_LISTS, VISIBILITY_DEPTH};
use ml_cpu::gpu_types::{CullCounters, LayerObject};
use ml_cpu::scene::Object;
use ml_vk::commands::{memory_barrier, one_shot, update_buffer};
use ml_vk::{vk, Buffer, Context, MemoryLocation, VkError};

/// The compute raster's buffers a frame slot's build binds, by their shader blocks' names
/// (its meshlets, counters and candidates; the visibility passes own them).
pub type RasterBuffers = Box<dyn Fn(usize, &str) -> Option<Resource>>;

/// Work groups of one dispatch along x (Vulkan's least maxComputeWorkGroupCount): the
/// per-triangle build dispatches a texture set's triangles in pieces of this many groups.
const MAX_GROUPS_X: u32 = 65_535;

/// Words per texture set in the listed triangles' counts (layer_triangles.glsl
/// LIST_WORDS): the two lists' lengths, then the large triangles' and the tiles' work groups
/// (VkDispatchIndirectCommand at words 4 and 8), which the per-triangle build raises.
const LIST_WORDS: usize = 12;

/// The listed triangles' counts of `sets` texture sets as a frame starts, for an image
/// `tile_rows` tiles high: nothing listed, no work groups.
fn empty_lists(sets: usize, tile_rows: u32) -> Vec<u32> {
    let one = [0, 0, 0, 0, 0, 1, 1, 0, 0, tile_rows, 1, 0];
    one.repeat(sets)
}

pub struct TransparentBuild {
    /// The tiles' build: objects of few triangles, and the huge triangles of the others.
    tiles: ComputePass,
    /// The per-triangle build of the other objects.
    triangles: ComputePass,
    /// Their triangles too large for a thread, a work group each.
    large: ComputePass,
    /// The cores' candidates the compute raster listed (`candidates`).
    listed: ComputePass,
    /// The compute raster's meshlets, counters and candidates (with its buffer).
    raster_buffers: Option<RasterBuffers>,
    /// The raster lists the cores' candidates.
    candidates: bool,
    /// Set 3 of the builds, per frame slot: the meshes, the slot's entries and the listed
    /// triangles' counts.
    mesh_sets: FrameSets,
    /// The transparent objects' meshes one after another.
    meshes: LayerMeshes,
    /// Per frame slot, the frame's entries (`LayerObject`), written as its commands are
    /// recorded: room for every transparent object, then for every triangle of the objects
    /// built a thread per triangle (each may be listed for the tiles' build).
    object_lists: Vec<Buffer>,
    /// Per frame slot, per texture set, the triangles the per-triangle build listed: for a
    /// work group each, and huge ones for the tiles' build.
    large_counts: Vec<Buffer>,
    /// The lists' pool size, per pixel.
    settings: TransparencySettings,
    /// Per frame slot, the lists (made with the slot, for its image size), which the frame's
    /// table names for the resolve.
    layers: Vec<Option<LayerBuffers>>,
    /// The opaque depth is the compute raster's 64-bit buffer (else the depth target).
    depth_buffer: bool,
}

/// The push constants of both builds (layer_triangles.glsl LayerDispatchBlock).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DispatchPush {
    objects: [u32; 4],
    large_list: [u32; 4],
}

impl TransparentBuild {
    /// The build over the compute raster's buffer where `depth_buffer` (its meshlets, counters
    /// and candidates in `raster_buffers`; it lists the cores' candidates where
    /// `candidates`), else over the depth target.
    pub fn new(
        ctx: &Context,
        (scene, objects, raster_buffers): (&SceneGpu, &[Object], Option<RasterBuffers>),
        (shading, settings): (Shading, TransparencySettings),
        (depth_buffer, candidates): (bool, bool),
    ) -> Result<TransparentBuild, VkError> {
        use ml_shaders as s;
        let (tiles, triangles, large) = if depth_buffer {
            (
                &s::TRANSPARENT_BUILD_COMPUTE_BUFFER_COMP,
                &s::TRANSPARENT_BUILD_TRIANGLES_BUFFER_COMP,
                &s::TRANSPARENT_BUILD_LARGE_BUFFER_COMP,
            )
        } else {
            (&s::TRANSPARENT_BUILD_COMPUTE_COMP, &s::TRANSPARENT_BUILD_TRIANGLES_COMP, &s::TRANSPARENT_BUILD_LARGE_COMP)
        };
        let listed = &s::TRANSPARENT_BUILD_CANDIDATES_COMP;
        let compute = vk::ShaderStageFlags::COMPUTE;
        let mut stages = vec![(tiles, compute), (triangles, compute), (large, compute)];
        if depth_buffer {
            stages.push((listed, compute));
        }
        let mesh_sets = FrameSets::new(ctx, &stages, 3, FRAMES_IN_FLIGHT)?;
        let layouts = [scene.textures.set_layout.raw, scene.object_textures.set_layout, mesh_sets.layout.raw];
        // From the compute raster's buffer, the fragments keep the samples they cover.
        let mut constants = shading.surface_constants().to_vec();
        constants.extend(shading.cores_constant());
        if depth_buffer {
            constants.push(shading.antialiasing.constant());
        }
        let push = std::mem::size_of::<DispatchPush>() as u32;
        let pass = TransparentBuild {
            tiles: ComputePass::empty(),
            triangles: ComputePass::empty(),
            large: ComputePass::empty(),
            listed: ComputePass::empty(),
            raster_buffers,
            candidates: candidates && depth_buffer,
            mesh_sets,
            meshes: LayerMeshes { vertices: Buffer::null(), indices: Buffer::null(), places: Vec::new() },
            object_lists: Vec::new(),
            large_counts: Vec::new(),
            settings,
            layers: (0..FRAMES_IN_FLIGHT).map(|_| None).collect(),
            depth_buffer,
        };
        ml_vk::build(ctx, pass, |pass| {
            pass.tiles = ComputePass::with_push(ctx, &layouts, (tiles, &constants), push)?;
            pass.triangles = ComputePass::with_push(ctx, &layouts, (triangles, &constants), push)?;
            pass.large = ComputePass::with_push(ctx, &layouts, (large, &constants), push)?;
            if pass.candidates {
                pass.listed = ComputePass::with_push(ctx, &layouts, (listed, &constants), push)?;
            }
            pass.meshes = LayerMeshes::new(ctx, &scene.meshes, objects)?;
            // Room for every transparent object and every triangle the per-triangle build may
            // list: a list never overflows.
            let transparent = objects.iter().filter_map(|o| layer_mesh(o, &scene.meshes)).map(|m| scene.meshes.meshes[m].index_count / 3);
            let (count, listed) = transparent.fold((0u64, 0u64), |(n, t), triangles| {
                (n + 1, t + if triangles > settings.tiled_up_to { u64::from(triangles) } else { 0 })
            });
            let bytes = (count + listed).max(1) * std::mem::size_of::<LayerObject>() as u64;
            let max = u64::from(ctx.info.limits.max_storage_buffer_range);
            if bytes > max {
                return Err(VkError::DeviceLimit(format!(
                    "the transparent objects' {listed} triangles built a thread each need a list of {bytes} bytes, more than device '{}' binds as one storage buffer ({max})",
                    ctx.info.name
                )));
            }
            let sets = scene.object_textures.sets.len().max(1) as u64;
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
            for _ in 0..FRAMES_IN_FLIGHT {
                pass.object_lists.push(Buffer::new(ctx, "transparent objects", bytes, usage, MemoryLocation::GpuOnly)?);
                let bytes = sets * (LIST_WORDS * 4) as u64;
                let usage = usage | vk::BufferUsageFlags::INDIRECT_BUFFER;
                pass.large_counts.push(Buffer::new(ctx, "listed transparent triangles", bytes, usage, MemoryLocation::GpuOnly)?);
            }
            Ok(())
        })
    }

    /// The frame's transparent objects as entries: per texture set those built over tiles,
    /// then those built a thread per triangle (their first triangle counted over the set's
    /// in `place.w`), then room for the large triangles of the latter; and per texture set
    /// where its entries lie.
    fn object_list(&self, rec: &Recording) -> (Vec<LayerObject>, Vec<ObjectGroup>) {
        let scene = rec.scene;
        let mut listed: Vec<(u32, Build, LayerObject)> = Vec::new();
        for (index, o) in rec.objects.iter().enumerate() {
            let Some(m) = layer_mesh(o, &scene.meshes) else { continue };
            let Some(((x, y), size)) = screen_rect(o.bounds(), rec.view_proj, rec.extent) else { continue };
            let (first_vertex, first_index) = self.meshes.places[m].expect("a transparent object's mesh is among the build's");
            let end = (y + size.height) << 16 | (x + size.width);
            let triangles = scene.meshes.meshes[m].index_count / 3;
            let ids = [index as u32, o.textures.bits(), first_index, triangles];
            let entry = LayerObject { ids, place: [first_vertex, y << 16 | x, end, 0] };
            let build = if self.candidates && o.extras.has_core() {
                Build::Cores
            } else if triangles > self.settings.tiled_up_to {
                Build::PerTriangle
            } else {
                Build::Tiles
            };
            listed.push((scene.object_textures.set_index[index], build, entry));
        }
        listed.sort_by_key(|(set, build, _)| (*set, *build));
        object_groups(listed)
    }

    /// Record the build: the slot's entries written; per texture set, its tiles' dispatch
    /// over the rectangle its small objects span, the per-triangle dispatch, the large
    /// triangles' dispatch, then the tiles' dispatch of the huge ones over the whole image.
    fn record_compute(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let (entries, groups) = self.object_list(rec);
        if groups.is_empty() {
            return;
        }
        update_buffer(ctx, cmd, self.object_lists[rec.slot].raw, bytemuck::cast_slice(&entries));
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        memory_barrier(
            ctx,
            cmd,
            (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
            (compute, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE),
        );
        let [tile_x, tile_y, _] = self.tiles.workgroup_size();
        let per_group = self.triangles.workgroup_size()[0];
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let mut first_dispatch = true;
        // The tiles' build stores its pixels' heads without atomics: every dispatch after the
        // earlier ones.
        let mut after_earlier = || {
            if !std::mem::take(&mut first_dispatch) {
                memory_barrier(ctx, cmd, (compute, rw), (compute, rw));
            }
        };
        for g in &groups {
            let sets = [rec.scene.textures.set, rec.scene.object_textures.sets[g.set as usize], self.mesh_sets.sets[rec.slot]];
            if let Some((lo, end)) = g.tiled_rect {
                after_earlier();
                // Tiles aligned with the resolve's (a pixel's nodes then lie together).
                let origin = (lo.0 / tile_x * tile_x, lo.1 / tile_y * tile_y);
                let size = vk::Extent2D { width: end.0 - origin.0, height: end.1 - origin.1 };
                let push = DispatchPush { objects: [g.first, g.tiled, origin.1 << 16 | origin.0, 0], large_list: [0; 4] };
                self.tiles.dispatch(ctx, cmd, rec.slot, (&sets, bytemuck::bytes_of(&push)), size);
            }
            if g.triangles == 0 {
                continue;
            }
            let large = g.set + 1;
            let large_list = [g.large_first, g.triangles, 0, 0];
            let piece = MAX_GROUPS_X * per_group;
            // The others' triangles, then the cores' (which return at once where the raster
            // listed their candidates).
            let core_first = g.triangles - g.core_triangles;
            for (range, cores) in [(0..core_first, 0), (core_first..g.triangles, 1)] {
                for base in range.clone().step_by(piece as usize) {
                    after_earlier();
                    let count = (range.end - base).min(piece);
                    let push = DispatchPush {
                        objects: [g.first + g.tiled, g.per_triangle, g.triangles, large],
                        large_list: [large_list[0], large_list[1], base, cores],
                    };
                    let push = (&sets[..], bytemuck::bytes_of(&push));
                    self.triangles.dispatch(ctx, cmd, rec.slot, push, vk::Extent2D { width: count, height: 1 });
                }
            }
            let counters = self.raster_buffers.as_ref().and_then(|find| find(rec.slot, CULL_COUNTERS.0));
            if let Some(Resource::Buffer(counters)) = counters.filter(|_| g.core_triangles > 0) {
                after_earlier();
                let push = DispatchPush { objects: [g.set, 0, 0, 0], large_list: [0; 4] };
                let groups = std::mem::offset_of!(CullCounters, candidate_groups) as u64;
                self.listed.dispatch_indirect(ctx, cmd, rec.slot, (&sets, bytemuck::bytes_of(&push)), (counters, groups));
            }
            // The lists and their work groups, as the per-triangle build left them.
            let indirect = vk::PipelineStageFlags::DRAW_INDIRECT;
            memory_barrier(ctx, cmd, (compute, rw), (compute | indirect, rw | vk::AccessFlags::INDIRECT_COMMAND_READ));
            let push = DispatchPush { objects: [0, 0, 0, large], large_list };
            let counts = (self.large_counts[rec.slot].raw, (g.set as usize * LIST_WORDS * 4) as u64);
            let push = (&sets[..], bytemuck::bytes_of(&push));
            self.large.dispatch_indirect(ctx, cmd, rec.slot, push, (counts.0, counts.1 + 16));
            memory_barrier(ctx, cmd, (compute, rw), (compute, rw));
            self.tiles.dispatch_indirect(ctx, cmd, rec.slot, push, (counts.0, counts.1 + 32));
        }
    }
}

/// Which build takes an object's triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Build {
    /// The tiles' (few triangles).
    Tiles,
    /// A thread a triangle.
    PerTriangle,
    /// The candidates' (a core the compute raster lists), else a thread a triangle.
    Cores,
}

/// One texture set's transparent objects in the frame's entries: `tiled` built over tiles
/// from `first` on (the rectangle they span, if any), then `per_triangle` built a thread per
/// triangle (`triangles` in all, of which the last `core_triangles` are cores), and the room
/// for their large triangles from `large_first`.
#[derive(Debug, PartialEq)]
struct ObjectGroup {
    set: u32,
    first: u32,
    tiled: u32,
    tiled_rect: Option<((u32, u32), (u32, u32))>,
    per_triangle: u32,
    triangles: u32,
    core_triangles: u32,
    large_first: u32,
}

/// `listed` (texture set, build, entry), sorted by set then build, as the frame's entries
/// (the per-triangle ones, cores among them, numbering their first triangle in `place.w`,
/// room for their large triangles after all of them) and its groups.
fn object_groups(listed: Vec<(u32, Build, LayerObject)>) -> (Vec<LayerObject>, Vec<ObjectGroup>) {
    let corner = |packed: u32| (packed & 0xffff, packed >> 16);
    let mut groups: Vec<ObjectGroup> = Vec::new();
    let mut entries = Vec::with_capacity(listed.len());
    for (set, build, mut entry) in listed {
        if groups.last().is_none_or(|g| g.set != set) {
            let first = entries.len() as u32;
            groups.push(ObjectGroup {
                set,
                first,
                tiled: 0,
                tiled_rect: None,
                per_triangle: 0,
                triangles: 0,
                core_triangles: 0,
                large_first: 0,
            });
        }
        let g = groups.last_mut().expect("just pushed");
        if build != Build::Tiles {
            entry.place[3] = g.triangles;
            g.per_triangle += 1;
            g.triangles += entry.ids[3];
            if build == Build::Cores {
                g.core_triangles += entry.ids[3];
            }
        } else {
            let (lo, end) = (corner(entry.place[1]), corner(entry.place[2]));
            g.tiled += 1;
            g.tiled_rect = Some(match g.tiled_rect {
                Some((l, e)) => ((l.0.min(lo.0), l.1.min(lo.1)), (e.0.max(end.0), e.1.max(end.1))),
                None => (lo, end),
            });
        }
        entries.push(entry);
    }
    let mut room = entries.len() as u32;
    for g in &mut groups {
        g.large_first = room;
        room += g.triangles;
    }
    (entries, groups)
}

/// The transparent objects' meshes in one vertex and one index buffer.
struct LayerMeshes {
    vertices: Buffer,
    indices: Buffer,
    /// Per mesh of the scene: where it starts in them (first vertex, first index), if a
    /// transparent object draws it.
    places: Vec<Option<(u32, u32)>>,
}

impl LayerMeshes {
    /// Copied on the GPU from the scene's meshes.
    fn new(ctx: &Context, scene_meshes: &SceneMeshes, objects: &[Object]) -> Result<LayerMeshes, VkError> {
        let meshes = &scene_meshes.meshes;
        let vertex_bytes = std::mem::size_of::<ml_cpu::mesh::Vertex>() as u64;
        let mut drawn = vec![false; meshes.len()];
        for m in objects.iter().filter_map(|o| layer_mesh(o, scene_meshes)) {
            drawn[m] = true;
        }
        let (mut vertex_count, mut index_count) = (0u64, 0u64);
        let mut places = Vec::new();
        for (m, &drawn) in meshes.iter().zip(&drawn) {
            places.push(drawn.then_some((vertex_count as u32, index_count as u32)));
            if drawn {
                vertex_count += u64::from(m.vertex_count);
                index_count += u64::from(m.index_count);
            }
        }
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let made = LayerMeshes { vertices: Buffer::null(), indices: Buffer::null(), places };
        // Vulkan has no empty buffers: one vertex and index where no object is transparent.
        ml_vk::build(ctx, made, |made| {
            made.vertices =
                Buffer::new(ctx, "transparent mesh vertices", vertex_count.max(1) * vertex_bytes, usage, MemoryLocation::GpuOnly)?;
            made.indices = Buffer::new(ctx, "transparent mesh indices", index_count.max(1) * 4, usage, MemoryLocation::GpuOnly)?;
            if vertex_count == 0 {
                return Ok(());
            }
            one_shot(ctx, |cmd| {
                for (m, place) in meshes.iter().zip(&made.places) {
                    // Vulkan copies nothing empty (a mesh without triangles draws nothing anyway).
                    let Some((first_vertex, first_index)) = place.filter(|_| m.vertex_count > 0 && m.index_count > 0) else { continue };
                    let vertices = [vk::BufferCopy::default()
                        .src_offset(u64::from(m.first_vertex) * vertex_bytes)
                        .dst_offset(u64::from(first_vertex) * vertex_bytes)
                        .size(u64::from(m.vertex_count) * vertex_bytes)];
                    let indices = [vk::BufferCopy::default()
                        .src_offset(u64::from(m.first_index) * 4)
                        .dst_offset(u64::from(first_index) * 4)
                        .size(u64::from(m.index_count) * 4)];
                    // SAFETY: recording; the buffers are alive and hold these ranges.
                    unsafe {
                        ctx.device.cmd_copy_buffer(cmd, scene_meshes.vertices.raw, made.vertices.raw, &vertices);
                        ctx.device.cmd_copy_buffer(cmd, scene_meshes.indices.raw, made.indices.raw, &indices);
                    }
                }
                let shaders = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ);
                memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), shaders);
            })
        })
    }
}

impl ml_vk::Release for LayerMeshes {
    fn release(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
    }
}

/// The pixels an object whose world box is `(lo, hi)` may cover in an image of `extent` seen
/// through `view_proj`: the box's corners projected, a pixel of margin, clamped to the image
/// (the whole image where the box reaches behind the eye); None where it covers none (wholly
/// behind the eye, or outside the image).
fn screen_rect((lo, hi): (glam::Vec3, glam::Vec3), view_proj: glam::Mat4, extent: vk::Extent2D) -> Option<((u32, u32), vk::Extent2D)> {
    let size = glam::Vec2::new(extent.width as f32, extent.height as f32);
    let corners = (0..8).map(|i| {
        let corner = glam::Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][(i >> 2) & 1]);
        view_proj * corner.extend(1.0)
    });
    let behind = corners.clone().filter(|c| c.w <= 1e-6).count();
    let (mut min, mut max) = (glam::Vec2::splat(f32::INFINITY), glam::Vec2::splat(f32::NEG_INFINITY));
    match behind {
        8 => return None,
        0 => {
            for clip in corners {
                let pixel = (clip.truncate().truncate() / clip.w + 1.0) * 0.5 * size;
                (min, max) = (min.min(pixel), max.max(pixel));
            }
        }
        _ => (min, max) = (glam::Vec2::ZERO, size),
    }
    let min = (min - 1.0).floor().max(glam::Vec2::ZERO);
    let max = (max + 1.0).ceil().min(size);
    (max.x > min.x && max.y > min.y).then(|| {
        let origin = (min.x as u32, min.y as u32);
        (origin, vk::Extent2D { width: max.x as u32 - origin.0, height: max.y as u32 - origin.1 })
    })
}

impl Pass for TransparentBuild {
    fn timer_name(&self) -> Option<&'static str> {
        Some("transparent layers")
    }

    /// Set 0 from the frame's table; set 3: the meshes, the slot's entries and lists and,
    /// over the compute raster's buffer, its meshlets, counters and candidates.
    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.tiles.bind_frame(ctx, frame)?;
        self.triangles.bind_frame(ctx, frame)?;
        self.large.bind_frame(ctx, frame)?;
        if self.candidates {
            self.listed.bind_frame(ctx, frame)?;
        }
        let (vertices, indices) = (self.meshes.vertices.raw, self.meshes.indices.raw);
        let (entries, large) = (self.object_lists[frame.slot].raw, self.large_counts[frame.slot].raw);
        let raster = self.raster_buffers.as_ref();
        self.mesh_sets.write(ctx, frame.slot, &|name| match name {
            "MeshVertexBuffer" => Some(Resource::Buffer(vertices)),
            "MeshIndexBuffer" => Some(Resource::Buffer(indices)),
            "LayerObjectBuffer" => Some(Resource::Buffer(entries)),
            "LargeTriangleCountBuffer" => Some(Resource::Buffer(large)),
            _ => raster.and_then(|find| find(frame.slot, name)),
        })
    }

    /// Clears and appends to the lists (after the earlier frame's readers of this slot's); reads
    /// the compute raster's depth. The depth target is ordered by the opaque raster's render
    /// pass, whose outgoing dependency reaches compute shaders.
    fn uses(&self) -> Vec<Use> {
        let shaders = vk::PipelineStageFlags::COMPUTE_SHADER;
        let stages = vk::PipelineStageFlags::TRANSFER | shaders;
        let access = vk::AccessFlags::TRANSFER_WRITE | vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let mut uses: Vec<Use> = LAYER_BUFFERS.iter().map(|&name| Use::buffer(name, (stages, access))).collect();
        if self.depth_buffer {
            uses.push(Use::buffer(VISIBILITY_DEPTH, (shaders, vk::AccessFlags::SHADER_READ)));
            uses.push(Use::buffer(DEPTH_PYRAMID, (shaders, vk::AccessFlags::SHADER_READ)));
            // The raster's counters (whether it listed the cores' candidates; their work
            // groups) and candidates.
            let indirect = vk::PipelineStageFlags::DRAW_INDIRECT;
            let counters = vk::AccessFlags::SHADER_READ | vk::AccessFlags::INDIRECT_COMMAND_READ;
            uses.push(Use::buffer(CULL_COUNTERS, (shaders | indirect, counters)));
            uses.push(Use::buffer(LAYER_CANDIDATES, (shaders, vk::AccessFlags::SHADER_READ)));
        }
        // Bound with the rest of set 0 (the surface code reads no light).
        uses.push(Use::buffer(LIGHT_LISTS[0], (shaders, vk::AccessFlags::SHADER_READ)));
        uses
    }

    fn record(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let layers = self.layers[rec.slot].as_ref().expect("the slot's lists made with the slot");
        // SAFETY: recording state outside a render pass; the buffers are alive.
        unsafe {
            ctx.device.cmd_fill_buffer(cmd, layers.heads.raw, 0, vk::WHOLE_SIZE, super::LAYER_END);
            ctx.device.cmd_fill_buffer(cmd, layers.counts.raw, 0, vk::WHOLE_SIZE, 0);
        }
        let sets = rec.scene.object_textures.sets.len().max(1);
        let tile_rows = rec.extent.height.div_ceil(self.tiles.workgroup_size()[1]);
        update_buffer(ctx, cmd, self.large_counts[rec.slot].raw, bytemuck::cast_slice(&empty_lists(sets, tile_rows)));
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let transfer = (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE);
        memory_barrier(ctx, cmd, transfer, (vk::PipelineStageFlags::COMPUTE_SHADER, rw));
        self.record_compute(rec);
    }

    fn destroy(&mut self, ctx: &Context) {
        self.tiles.destroy(ctx);
        self.triangles.destroy(ctx);
        self.large.destroy(ctx);
        self.listed.destroy(ctx);
        self.mesh_sets.destroy(ctx);
        ml_vk::Release::release(&mut self.meshes, ctx);
        for list in self.object_lists.iter_mut().chain(&mut self.large_counts) {
            list.destroy(ctx);
        }
        self.object_lists.clear();
        self.large_counts.clear();
        for mut layers in self.layers.iter_mut().filter_map(Option::take) {
            layers.destroy(ctx);
        }
    }

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for TransparentBuild {
    fn create_slot(&mut self, ctx: &Context, slot: usize, extent: vk::Extent2D) -> Result<(), VkError> {
        if let Some(mut old) = self.layers[slot].take() {
            old.destroy(ctx);
        }
        self.layers[slot] = Some(LayerBuffers::new(
            ctx,
            extent,
            (self.settings.nodes(extent.width, extent.height), node_bytes(self.settings.lobe_textures)),
        )?);
        Ok(())
    }

    fn slot_buffers(&self, slot: usize) -> Vec<(BufferName, vk::Buffer)> {
        self.layers[slot].as_ref().map_or_else(Vec::new, |l| l.named().to_vec())
    }

    fn host_reads(&self, _slot: usize) -> Vec<HostRead> {
        vec![HostRead::in_place(LAYER_BUFFERS[2])]
    }

    fn collect(&self, slot: usize, _: &mut SlotReport, stats: &mut FrameStats) {
        let Some(layers) = self.layers[slot].as_ref() else { return };
        let [fragments, merged, group_triangles, tiled_triangles] = layers.counts();
        stats.set_feature(TransparencyStats {
            fragments: fragments as u64,
            capacity: layers.capacity(),
            node_bytes: layers.node_bytes,
            pixels: layers.pixels(),
            merged_pixels: merged as u64,
            group_triangles: group_triangles as u64,
            tiled_triangles: tiled_triangles as u64,
        });
    }
}

impl ml_vk::Release for TransparentBuild {
    fn release(&mut self, ctx: &Context) {
        Pass::destroy(self, ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3};

    #[test]
    fn each_texture_sets_objects_make_its_dispatches_and_room_for_listed_triangles() {
        let entry = |lo: (u32, u32), end: (u32, u32), triangles: u32| LayerObject {
            ids: [0, 0, 0, triangles],
            place: [0, lo.1 << 16 | lo.0, end.1 << 16 | end.0, 0],
        };
        let listed = vec![
            (0, Build::Tiles, entry((10, 20), (30, 40), 2)),
            (0, Build::Tiles, entry((5, 30), (20, 50), 2)),
            (0, Build::PerTriangle, entry((0, 0), (90, 90), 100)),
            (0, Build::Cores, entry((0, 0), (90, 90), 300)),
            (2, Build::PerTriangle, entry((100, 0), (120, 16), 70)),
        ];
        let (entries, groups) = object_groups(listed);
        assert_eq!(
            groups,
            [
                ObjectGroup {
                    set: 0,
                    first: 0,
                    tiled: 2,
                    tiled_rect: Some(((5, 20), (30, 50))),
                    per_triangle: 2,
                    triangles: 400,
                    core_triangles: 300,
                    large_first: 5
                },
                ObjectGroup {
                    set: 2,
                    first: 4,
                    tiled: 0,
                    tiled_rect: None,
                    per_triangle: 1,
                    triangles: 70,
                    core_triangles: 0,
                    large_first: 405
                }
            ]
        );
        // The per-triangle entries number their first triangle within their set's.
        assert_eq!(entries.iter().map(|e| e.place[3]).collect::<Vec<_>>(), [0, 0, 0, 100, 0]);
        assert_eq!(object_groups(Vec::new()), (Vec::new(), Vec::new()));
    }

    #[test]
    fn an_objects_screen_rectangle_holds_its_box_and_no_more_than_the_image() {
        let extent = vk::Extent2D { width: 200, height: 100 };
        let camera = ml_cpu::camera::Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 60.0, 0.1, 50.0);
        let vp: Mat4 = camera.projection(2.0) * camera.view();
        // A small box ahead: a rectangle round the middle of the image.
        let ((x, y), size) = screen_rect((Vec3::splat(-0.5), Vec3::splat(0.5)), vp, extent).expect("in view");
        assert!(x > 50 && x < 100 && y > 20 && y < 50 && size.width < 100 && size.height < 60, "{x} {y} {size:?}");
        assert!(x + size.width > 100 && y + size.height > 50);
        // Reaching behind the eye: the whole image; wholly behind it, or off to a side: nothing.
        assert_eq!(screen_rect((Vec3::splat(-1.0), Vec3::new(1.0, 1.0, 9.0)), vp, extent), Some(((0, 0), extent)));
        assert_eq!(screen_rect((Vec3::new(-1.0, -1.0, 6.0), Vec3::new(1.0, 1.0, 9.0)), vp, extent), None);
        assert_eq!(screen_rect((Vec3::new(40.0, -1.0, -1.0), Vec3::new(41.0, 1.0, 1.0)), vp, extent), None);
    }
}
