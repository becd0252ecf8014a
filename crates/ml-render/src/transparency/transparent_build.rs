//! The transparent layers' build: each fragment of a transparent object in front of the opaque
//! depth appended to its pixel's list (layers.glsl). Objects of few triangles (panes, cards)
//! are rasterised in compute, a dispatch each (transparent_build_compute.glsl: the H100 runs
//! fragment shaders on 4 of its 132 SMs); the others are drawn by the hardware raster with no
//! attachments (transparent_build.frag). Runs after the opaque raster, before the resolve;
//! clears the slot's lists first.

use super::{TransparencyStats, LAYER_BUFFERS};
use crate::compute_pass::ComputePass;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::gpu_mesh::compute_layer_mesh;
use crate::pass::{Pass, Recording, SlotReport};
use crate::report::FrameStats;
use crate::scene::object_data::object_push;
use crate::scene::SceneGpu;
use crate::shading::mesh_raster::MeshRaster;
use crate::shading::Shading;
use crate::sync::{Use, VISIBILITY_DEPTH};
use crate::targets::{Output, Targets};
use ml_cpu::gpu_types::ObjectPush;
use ml_vk::commands::memory_barrier;
use ml_vk::image::fetch_sampler;
use ml_vk::{vk, Context, VkError};

pub struct TransparentBuild {
    raster: MeshRaster,
    /// The compute build of small transparent objects.
    compute: ComputePass,
    /// Set 3 of the compute build: each mesh's vertices and indices, by the mesh's index.
    mesh_sets: FrameSets,
    /// Reads the opaque depth image.
    sampler: vk::Sampler,
    /// The opaque depth is the compute raster's 64-bit buffer (else the depth target).
    depth_buffer: bool,
}

impl TransparentBuild {
    pub fn new(ctx: &Context, scene: &SceneGpu, shading: Shading, depth_buffer: bool) -> Result<TransparentBuild, VkError> {
        let (fragment, kernel) = if depth_buffer {
            (&ml_shaders::TRANSPARENT_BUILD_BUFFER_FRAG, &ml_shaders::TRANSPARENT_BUILD_COMPUTE_BUFFER_COMP)
        } else {
            (&ml_shaders::TRANSPARENT_BUILD_FRAG, &ml_shaders::TRANSPARENT_BUILD_COMPUTE_COMP)
        };
        let layouts = (scene.textures.set_layout.raw, scene.object_textures.set_layout);
        // No depth attachment: the format is not used.
        let output = (vk::Format::UNDEFINED, Output::Layers { depth_buffer }, &[][..]);
        let mut raster = MeshRaster::new(ctx, output, (fragment, shading, &scene.surface_variants), layouts)?;
        let mut mesh_sets = match FrameSets::new(ctx, &[(kernel, vk::ShaderStageFlags::COMPUTE)], 3, scene.meshes.len().max(1)) {
            Ok(sets) => sets,
            Err(e) => {
                raster.destroy(ctx);
                return Err(e);
            }
        };
        let constants = shading.surface_constants();
        let more = [layouts.0, layouts.1, mesh_sets.layout.raw];
        let push = std::mem::size_of::<ObjectPush>() as u32;
        let compute = match ComputePass::with_push(ctx, &more, (kernel, &constants), push) {
            Ok(c) => c,
            Err(e) => {
                raster.destroy(ctx);
                mesh_sets.destroy(ctx);
                return Err(e);
            }
        };
        let mut pass = TransparentBuild { raster, compute, mesh_sets, sampler: vk::Sampler::null(), depth_buffer };
        let made = (|| {
            for (i, mesh) in scene.meshes.iter().enumerate() {
                pass.mesh_sets.write(ctx, i, &|name| match name {
                    "MeshVertexBuffer" => Some(Resource::Buffer(mesh.vertices.raw)),
                    "MeshIndexBuffer" => Some(Resource::Buffer(mesh.indices.raw)),
                    _ => None,
                })?;
            }
            pass.sampler = fetch_sampler(ctx)?;
            Ok(())
        })();
        match made {
            Ok(()) => Ok(pass),
            Err(e) => {
                pass.destroy(ctx);
                Err(e)
            }
        }
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
        let layers = rec.targets.layers.as_ref().expect("targets made with the layers the plan builds");
        // SAFETY: recording state outside a render pass; the buffers are alive.
        unsafe {
            ctx.device.cmd_fill_buffer(cmd, layers.heads.raw, 0, vk::WHOLE_SIZE, super::LAYER_END);
            ctx.device.cmd_fill_buffer(cmd, layers.counts.raw, 0, vk::WHOLE_SIZE, 0);
        }
        let (compute, fragment) = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::PipelineStageFlags::FRAGMENT_SHADER);
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute | fragment, rw));
        let scene = rec.scene;
        for (index, o) in rec.objects.iter().enumerate() {
            let Some(m) = compute_layer_mesh(o, &scene.meshes) else { continue };
            let Some((origin, size)) = screen_rect(o.bounds(), rec.view_proj, rec.extent) else { continue };
            let mut push = object_push(o, index as u32);
            push.ids[2] = scene.meshes[m].index_count / 3;
            push.ids[3] = origin.1 << 16 | origin.0;
            let sets = [scene.textures.set, scene.object_textures.per_object[index], self.mesh_sets.sets[m]];
            self.compute.dispatch(ctx, cmd, rec.slot, (&sets, bytemuck::bytes_of(&push)), size);
        }
        // The compute build's appends before the raster's (both swap list heads).
        memory_barrier(ctx, cmd, (compute, rw), (fragment, rw));
        self.raster.begin_and_draw_meshes(rec);
        // SAFETY: recording inside the render pass begun above.
        unsafe { ctx.device.cmd_end_render_pass(cmd) };
    }

    fn collect(&self, _slot: usize, targets: &Targets, _: &mut SlotReport, stats: &mut FrameStats) {
        let layers = targets.layers.as_ref().expect("targets made with the layers the plan builds");
        let [fragments, merged] = layers.counts();
        let extent = targets.color.extent;
        stats.set_feature(TransparencyStats {
            fragments: fragments as u64,
            capacity: layers.capacity(),
            pixels: extent.width as u64 * extent.height as u64,
            merged_pixels: merged as u64,
        });
    }

    fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no pending work uses it; a null handle is ignored.
        unsafe { ctx.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
        self.compute.destroy(ctx);
        self.mesh_sets.destroy(ctx);
        self.raster.destroy(ctx);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3};

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
