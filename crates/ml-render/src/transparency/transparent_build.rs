//! The transparent layers' build: each fragment of a transparent object in front of the opaque
//! depth appended to its pixel's list (layers.glsl). Objects of few triangles (panes, cards)
//! are rasterised in compute, one dispatch over the tiles their screen rectangles meet
//! (transparent_build_compute.glsl: the H100 runs fragment shaders on 4 of its 132 SMs); the
//! others are drawn by the hardware raster with no attachments (transparent_build.frag). Runs
//! after the opaque raster, before the resolve; clears the slot's lists first.

use super::{counts_to_host, LayerBuffers, TransparencySettings, TransparencyStats, LAYER_BUFFERS};
use crate::compute_pass::ComputePass;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::{FrameResources, FRAMES_IN_FLIGHT};
use crate::gpu_mesh::{compute_layer_mesh, GpuMesh};
use crate::pass::{Pass, Recording, SlotReport};
use crate::report::FrameStats;
use crate::scene::SceneGpu;
use crate::shading::mesh_raster::MeshRaster;
use crate::shading::Shading;
use crate::sync::{Use, VISIBILITY_DEPTH};
use crate::targets::Output;
use ml_cpu::gpu_types::LayerObject;
use ml_vk::commands::{memory_barrier, one_shot, update_buffer};
use ml_vk::image::fetch_sampler;
use ml_vk::{vk, Buffer, Context, MemoryLocation, VkError};

pub struct TransparentBuild {
    raster: MeshRaster,
    /// The compute build of small transparent objects.
    compute: ComputePass,
    /// Set 3 of the compute build, per frame slot: the small meshes and the slot's object list.
    mesh_sets: FrameSets,
    /// The small meshes (at most `COMPUTE_LAYER_TRIANGLES` triangles) one after another, and
    /// where each mesh of the scene's starts in them.
    small_meshes: SmallMeshes,
    /// Per frame slot, the frame's compute-built objects (`LayerObject`), written as its
    /// commands are recorded: room for every object of the scene.
    object_lists: Vec<Buffer>,
    /// The lists' pool size, per pixel.
    settings: TransparencySettings,
    /// Per frame slot, the lists (made with the slot, for its image size), which the frame's
    /// table names for the resolve.
    layers: Vec<Option<LayerBuffers>>,
    /// Reads the opaque depth image.
    sampler: vk::Sampler,
    /// The opaque depth is the compute raster's 64-bit buffer (else the depth target).
    depth_buffer: bool,
}

impl TransparentBuild {
    pub fn new(
        ctx: &Context,
        scene: &SceneGpu,
        (shading, settings): (Shading, TransparencySettings),
        depth_buffer: bool,
    ) -> Result<TransparentBuild, VkError> {
        let (fragment, kernel) = if depth_buffer {
            (&ml_shaders::TRANSPARENT_BUILD_BUFFER_FRAG, &ml_shaders::TRANSPARENT_BUILD_COMPUTE_BUFFER_COMP)
        } else {
            (&ml_shaders::TRANSPARENT_BUILD_FRAG, &ml_shaders::TRANSPARENT_BUILD_COMPUTE_COMP)
        };
        let layouts = (scene.textures.set_layout.raw, scene.object_textures.set_layout);
        // No depth attachment: the format is not used.
        let output = (vk::Format::UNDEFINED, Output::Layers { depth_buffer }, &[][..]);
        let mut raster = MeshRaster::new(ctx, output, (fragment, shading, &scene.surface_variants), layouts)?;
        let mut mesh_sets = match FrameSets::new(ctx, &[(kernel, vk::ShaderStageFlags::COMPUTE)], 3, FRAMES_IN_FLIGHT) {
            Ok(sets) => sets,
            Err(e) => {
                raster.destroy(ctx);
                return Err(e);
            }
        };
        let constants = shading.surface_constants();
        let more = [layouts.0, layouts.1, mesh_sets.layout.raw];
        let push = std::mem::size_of::<[u32; 4]>() as u32;
        let compute = match ComputePass::with_push(ctx, &more, (kernel, &constants), push) {
            Ok(c) => c,
            Err(e) => {
                raster.destroy(ctx);
                mesh_sets.destroy(ctx);
                return Err(e);
            }
        };
        let pass = TransparentBuild {
            raster,
            compute,
            mesh_sets,
            small_meshes: SmallMeshes { vertices: Buffer::null(), indices: Buffer::null(), places: Vec::new() },
            object_lists: Vec::new(),
            settings,
            layers: (0..FRAMES_IN_FLIGHT).map(|_| None).collect(),
            sampler: vk::Sampler::null(),
            depth_buffer,
        };
        ml_vk::build(ctx, pass, |pass| {
            pass.small_meshes = SmallMeshes::new(ctx, &scene.meshes)?;
            let objects = scene.object_textures.per_object.len().max(1);
            let bytes = (objects * std::mem::size_of::<LayerObject>()) as u64;
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
            for slot in 0..FRAMES_IN_FLIGHT {
                pass.object_lists.push(Buffer::new(ctx, "transparent objects", bytes, usage, MemoryLocation::GpuOnly)?);
                let (vertices, indices, objects) =
                    (pass.small_meshes.vertices.raw, pass.small_meshes.indices.raw, pass.object_lists[slot].raw);
                pass.mesh_sets.write(ctx, slot, &|name| match name {
                    "MeshVertexBuffer" => Some(Resource::Buffer(vertices)),
                    "MeshIndexBuffer" => Some(Resource::Buffer(indices)),
                    "LayerObjectBuffer" => Some(Resource::Buffer(objects)),
                    _ => None,
                })?;
            }
            pass.sampler = fetch_sampler(ctx)?;
            Ok(())
        })
    }

    /// The frame's compute-built objects, those of one texture set side by side, and per
    /// texture set its objects' range in the list and the rectangle they may cover.
    fn object_list(&self, rec: &Recording) -> (Vec<LayerObject>, Vec<ObjectGroup>) {
        let scene = rec.scene;
        let mut listed: Vec<(u32, LayerObject)> = Vec::new();
        for (index, o) in rec.objects.iter().enumerate() {
            let Some(m) = compute_layer_mesh(o, &scene.meshes) else { continue };
            let Some(((x, y), size)) = screen_rect(o.bounds(), rec.view_proj, rec.extent) else { continue };
            let (first_vertex, first_index) = self.small_meshes.places[m].expect("a compute-built object's mesh is small");
            let end = (y + size.height) << 16 | (x + size.width);
            let ids = [index as u32, o.textures.bits(), first_index, scene.meshes[m].index_count / 3];
            listed.push((scene.object_textures.set_index[index], LayerObject { ids, place: [first_vertex, y << 16 | x, end, 0] }));
        }
        listed.sort_by_key(|(set, _)| *set);
        let groups = object_groups(&listed);
        (listed.into_iter().map(|(_, entry)| entry).collect(), groups)
    }

    /// Record the compute build: the slot's object list written, a dispatch per texture set
    /// over the tiles its objects' rectangles span.
    fn record_compute(&self, rec: &Recording) {
        let (ctx, cmd) = (rec.ctx, rec.cmd);
        let (entries, groups) = self.object_list(rec);
        if entries.is_empty() {
            return;
        }
        update_buffer(ctx, cmd, self.object_lists[rec.slot].raw, bytemuck::cast_slice(&entries));
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        memory_barrier(
            ctx,
            cmd,
            (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
            (compute, vk::AccessFlags::SHADER_READ),
        );
        let [tile_x, tile_y, _] = self.compute.workgroup_size();
        for (i, g) in groups.iter().enumerate() {
            if i > 0 {
                // Each dispatch stores its tiles' list heads without atomics.
                let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
                memory_barrier(ctx, cmd, (compute, rw), (compute, rw));
            }
            // Tiles aligned with the resolve's (a pixel's nodes then lie together).
            let origin = (g.lo.0 / tile_x * tile_x, g.lo.1 / tile_y * tile_y);
            let size = vk::Extent2D { width: g.end.0 - origin.0, height: g.end.1 - origin.1 };
            let push = [g.first, g.count, origin.1 << 16 | origin.0, 0];
            let sets = [rec.scene.textures.set, rec.scene.object_textures.sets[g.set as usize], self.mesh_sets.sets[rec.slot]];
            self.compute.dispatch(ctx, cmd, rec.slot, (&sets, bytemuck::bytes_of(&push)), size);
        }
    }
}

/// The compute-built objects of one texture set: their range in the frame's list and the
/// rectangle they may cover (first pixel, end).
#[derive(Debug, PartialEq)]
struct ObjectGroup {
    set: u32,
    first: u32,
    count: u32,
    lo: (u32, u32),
    end: (u32, u32),
}

/// The groups of `listed` (texture set, object), sorted by texture set.
fn object_groups(listed: &[(u32, LayerObject)]) -> Vec<ObjectGroup> {
    let corner = |packed: u32| (packed & 0xffff, packed >> 16);
    let mut groups: Vec<ObjectGroup> = Vec::new();
    for (i, (set, entry)) in listed.iter().enumerate() {
        let (lo, end) = (corner(entry.place[1]), corner(entry.place[2]));
        match groups.last_mut() {
            Some(g) if g.set == *set => {
                g.count += 1;
                g.lo = (g.lo.0.min(lo.0), g.lo.1.min(lo.1));
                g.end = (g.end.0.max(end.0), g.end.1.max(end.1));
            }
            _ => groups.push(ObjectGroup { set: *set, first: i as u32, count: 1, lo, end }),
        }
    }
    groups
}

/// The scene's small meshes (compute-built layers) in one vertex and one index buffer.
struct SmallMeshes {
    vertices: Buffer,
    indices: Buffer,
    /// Per mesh of the scene: where it starts in them (first vertex, first index), if small.
    places: Vec<Option<(u32, u32)>>,
}

impl SmallMeshes {
    /// Copied on the GPU from the scene's meshes.
    fn new(ctx: &Context, meshes: &[GpuMesh]) -> Result<SmallMeshes, VkError> {
        let vertex_bytes = std::mem::size_of::<ml_cpu::mesh::Vertex>() as u64;
        let small = |m: &GpuMesh| m.index_count / 3 <= crate::gpu_mesh::COMPUTE_LAYER_TRIANGLES;
        let (mut vertex_count, mut index_count) = (0u64, 0u64);
        let mut places = Vec::new();
        for m in meshes {
            places.push(small(m).then_some((vertex_count as u32, index_count as u32)));
            if small(m) {
                vertex_count += m.vertices.size / vertex_bytes;
                index_count += u64::from(m.index_count);
            }
        }
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let made = SmallMeshes { vertices: Buffer::null(), indices: Buffer::null(), places };
        // Vulkan has no empty buffers: one vertex and index where no mesh is small.
        ml_vk::build(ctx, made, |made| {
            made.vertices = Buffer::new(ctx, "small mesh vertices", vertex_count.max(1) * vertex_bytes, usage, MemoryLocation::GpuOnly)?;
            made.indices = Buffer::new(ctx, "small mesh indices", index_count.max(1) * 4, usage, MemoryLocation::GpuOnly)?;
            if vertex_count == 0 {
                return Ok(());
            }
            one_shot(ctx, |cmd| {
                for (m, place) in meshes.iter().zip(&made.places) {
                    // Vulkan copies nothing empty (a mesh without triangles draws nothing anyway).
                    let Some((first_vertex, first_index)) = place.filter(|_| m.vertices.size > 0 && m.index_count > 0) else { continue };
                    let vertices = [vk::BufferCopy::default().dst_offset(u64::from(first_vertex) * vertex_bytes).size(m.vertices.size)];
                    let indices = [vk::BufferCopy::default().dst_offset(u64::from(first_index) * 4).size(u64::from(m.index_count) * 4)];
                    // SAFETY: recording; the buffers are alive and hold these ranges.
                    unsafe {
                        ctx.device.cmd_copy_buffer(cmd, m.vertices.raw, made.vertices.raw, &vertices);
                        ctx.device.cmd_copy_buffer(cmd, m.indices.raw, made.indices.raw, &indices);
                    }
                }
                let shaders = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_READ);
                memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), shaders);
            })
        })
    }
}

impl ml_vk::Release for SmallMeshes {
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

    fn create_slot(&mut self, ctx: &Context, slot: usize, extent: vk::Extent2D) -> Result<(), VkError> {
        if let Some(mut old) = self.layers[slot].take() {
            old.destroy(ctx);
        }
        self.layers[slot] = Some(LayerBuffers::new(ctx, extent, self.settings.nodes(extent.width, extent.height))?);
        Ok(())
    }

    fn slot_buffers(&self, slot: usize) -> Vec<(&'static str, vk::Buffer)> {
        self.layers[slot].as_ref().map_or_else(Vec::new, |l| l.named().to_vec())
    }

    fn host_reads(&self) -> Vec<Use> {
        vec![counts_to_host()]
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        let depth = vk::DescriptorImageInfo::default()
            .sampler(self.sampler)
            .image_view(frame.targets.depth.view)
            .image_layout(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
        let extra = |name: &str| (name == "opaque_depth").then_some(Resource::Image(depth));
        self.raster.bind_frame_with(ctx, frame, &extra)?;
        self.compute.bind_frame(ctx, frame, &|name| extra(name).or_else(|| frame.buffer(name)))
    }

    /// Clears and appends to the lists (after the earlier frame's readers of this slot's); reads
    /// the compute raster's depth. The depth target is ordered by the opaque raster's render
    /// pass, whose outgoing dependency reaches compute and fragment shaders.
    fn uses(&self) -> Vec<Use> {
        let shaders = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::FRAGMENT_SHADER;
        let stages = vk::PipelineStageFlags::TRANSFER | shaders;
        let access = vk::AccessFlags::TRANSFER_WRITE | vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        let mut uses: Vec<Use> = LAYER_BUFFERS.iter().map(|&name| Use::at(name, (stages, access), None)).collect();
        if self.depth_buffer {
            uses.push(Use::at(VISIBILITY_DEPTH, (shaders, vk::AccessFlags::SHADER_READ), None));
        }
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
        let (compute, fragment) = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::PipelineStageFlags::FRAGMENT_SHADER);
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute | fragment, rw));
        self.record_compute(rec);
        // The compute build's nodes and heads before the raster's appends (which swap heads).
        memory_barrier(ctx, cmd, (compute, rw), (fragment, rw));
        self.raster.begin_and_draw_meshes(rec);
        // SAFETY: recording inside the render pass begun above.
        unsafe { ctx.device.cmd_end_render_pass(cmd) };
    }

    fn collect(&self, slot: usize, _: &mut SlotReport, stats: &mut FrameStats) {
        let Some(layers) = self.layers[slot].as_ref() else { return };
        let [fragments, merged] = layers.counts();
        stats.set_feature(TransparencyStats {
            fragments: fragments as u64,
            capacity: layers.capacity(),
            pixels: layers.pixels(),
            merged_pixels: merged as u64,
        });
    }

    fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses it; a null handle is ignored.
        unsafe { ctx.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
        self.compute.destroy(ctx);
        self.mesh_sets.destroy(ctx);
        ml_vk::Release::release(&mut self.small_meshes, ctx);
        for list in &mut self.object_lists {
            list.destroy(ctx);
        }
        self.object_lists.clear();
        for mut layers in self.layers.iter_mut().filter_map(Option::take) {
            layers.destroy(ctx);
        }
        self.raster.destroy(ctx);
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
    fn objects_of_one_texture_set_make_one_dispatch_over_their_rectangles() {
        let entry = |lo: (u32, u32), end: (u32, u32)| LayerObject { ids: [0; 4], place: [0, lo.1 << 16 | lo.0, end.1 << 16 | end.0, 0] };
        let listed = [(0, entry((10, 20), (30, 40))), (0, entry((5, 30), (20, 50))), (2, entry((100, 0), (120, 16)))];
        assert_eq!(
            object_groups(&listed),
            [
                ObjectGroup { set: 0, first: 0, count: 2, lo: (5, 20), end: (30, 50) },
                ObjectGroup { set: 2, first: 2, count: 1, lo: (100, 0), end: (120, 16) }
            ]
        );
        assert!(object_groups(&[]).is_empty());
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
