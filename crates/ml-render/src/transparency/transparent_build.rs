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
use crate::gpu_mesh::layers_in_compute;
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
        let constants = [&shading.surface_constants()[..], &[("TRANSPARENT_LAYERS", 1)]].concat();
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
        let layers = &rec.targets.layers;
        // SAFETY: recording state outside a render pass; the buffers are alive.
        unsafe {
            ctx.device.cmd_fill_buffer(cmd, layers.heads.raw, 0, vk::WHOLE_SIZE, super::LAYER_END);
            ctx.device.cmd_fill_buffer(cmd, layers.counts.raw, 0, vk::WHOLE_SIZE, 0);
        }
        let (compute, fragment) = (vk::PipelineStageFlags::COMPUTE_SHADER, vk::PipelineStageFlags::FRAGMENT_SHADER);
        let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
        memory_barrier(ctx, cmd, (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE), (compute | fragment, rw));
        let scene = rec.scene;
        for (index, o) in rec.objects.iter().enumerate().filter(|(_, o)| layers_in_compute(o, &scene.meshes)) {
            let Some(m) = scene.meshes.iter().position(|m| m.kind == o.mesh) else { continue };
            let mut push = object_push(o, index as u32);
            push.ids[2] = scene.meshes[m].index_count / 3;
            let sets = [scene.textures.set, scene.object_textures.per_object[index], self.mesh_sets.sets[m]];
            self.compute.dispatch(ctx, cmd, rec.slot, (&sets, bytemuck::bytes_of(&push)), rec.extent);
        }
        // The compute build's appends before the raster's (both swap list heads).
        memory_barrier(ctx, cmd, (compute, rw), (fragment, rw));
        self.raster.begin_and_draw_meshes(rec);
        // SAFETY: recording inside the render pass begun above.
        unsafe { ctx.device.cmd_end_render_pass(cmd) };
    }

    fn collect(&self, _slot: usize, targets: &Targets, _: &mut SlotReport, stats: &mut FrameStats) {
        let layers = &targets.layers;
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
