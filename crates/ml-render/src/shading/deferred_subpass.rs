//! Deferred shading in one render pass with two subpasses (techniques deferred,
//! deferred-clustered; docs/DESIGN.md#deferred-shading-in-one-render-pass): subpass 0 draws
//! every object into the G-buffer and depth, subpass 1 reads them as input attachments (this
//! pixel only) and lights a full-screen triangle into the HDR target — over every light, or
//! over the pixel's cluster — which the tone-map pass turns into the colour target.

use crate::antialiasing::Antialiasing;
use crate::descriptors::{FrameSets, Resource};
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::pass::{Pass, Recording};
use crate::scene::SceneGpu;
use crate::shading::gbuffer::gbuffer_shader;
use crate::shading::mesh_raster::{Draw, MeshRaster};
use crate::shading::Shading;
use crate::sync::{shading_reads, Use};
use crate::targets::{gbuffer_images, GBufferKind, Output};
use ml_vk::{shader, vk, Context, VkError};

pub struct DeferredSubpasses {
    raster: MeshRaster,
    /// The lighting subpass's set 0 (uniforms, lights, lists, objects, cones) and set 2 (the
    /// G-buffer and depth as input attachments), per frame slot.
    lighting_sets: FrameSets,
    input_sets: FrameSets,
    lighting_layout: vk::PipelineLayout,
    lighting: vk::Pipeline,
}

impl DeferredSubpasses {
    pub fn new(
        ctx: &Context,
        scene: &SceneGpu,
        (depth_format, shading): (vk::Format, Shading),
        clustered: bool,
    ) -> Result<DeferredSubpasses, VkError> {
        let kind = shading.gbuffer_kind();
        let gbuffer = gbuffer_shader(kind);
        // With anti-aliasing, the variant that reads the G-buffer's samples (a subpass input's
        // type says whether it is multisampled); a subpass may not name inputs it lacks, so
        // each kind of G-buffer has its own.
        let samples = shading.antialiasing != Antialiasing::Off;
        use GBufferKind::{Base, Lobes, Material};
        let lighting = match (clustered, kind, samples) {
            (false, Base, false) => &ml_shaders::DEFERRED_FRAG,
            (true, Base, false) => &ml_shaders::DEFERRED_CLUSTERED_FRAG,
            (false, Material, false) => &ml_shaders::DEFERRED_TEXTURED_FRAG,
            (true, Material, false) => &ml_shaders::DEFERRED_CLUSTERED_TEXTURED_FRAG,
            (false, Lobes, false) => &ml_shaders::DEFERRED_LOBES_FRAG,
            (true, Lobes, false) => &ml_shaders::DEFERRED_CLUSTERED_LOBES_FRAG,
            (false, Base, true) => &ml_shaders::DEFERRED_SAMPLES_FRAG,
            (true, Base, true) => &ml_shaders::DEFERRED_CLUSTERED_SAMPLES_FRAG,
            (false, Material, true) => &ml_shaders::DEFERRED_TEXTURED_SAMPLES_FRAG,
            (true, Material, true) => &ml_shaders::DEFERRED_CLUSTERED_TEXTURED_SAMPLES_FRAG,
            (false, Lobes, true) => &ml_shaders::DEFERRED_LOBES_SAMPLES_FRAG,
            (true, Lobes, true) => &ml_shaders::DEFERRED_CLUSTERED_LOBES_SAMPLES_FRAG,
        };
        let textures = scene.textures.set_layout.raw;
        let attachments = (depth_format, Output::Subpasses, gbuffer_images(kind));
        let raster =
            MeshRaster::new(ctx, attachments, (gbuffer, shading, &scene.surface_variants), (textures, scene.object_textures.set_layout))?;
        let stages = [(&ml_shaders::FULLSCREEN_VERT, vk::ShaderStageFlags::VERTEX), (lighting, vk::ShaderStageFlags::FRAGMENT)];
        let pass = DeferredSubpasses {
            raster,
            lighting_sets: FrameSets::empty(),
            input_sets: FrameSets::empty(),
            lighting_layout: vk::PipelineLayout::null(),
            lighting: vk::Pipeline::null(),
        };
        ml_vk::build(ctx, pass, |pass| {
            pass.lighting_sets = FrameSets::new(ctx, &stages, 0, FRAMES_IN_FLIGHT)?;
            pass.input_sets = FrameSets::new(ctx, &stages, 2, FRAMES_IN_FLIGHT)?;
            let layouts = [pass.lighting_sets.layout.raw, textures, pass.input_sets.layout.raw];
            pass.lighting_layout = shader::pipeline_layout(ctx, &layouts, &[])?;
            let shaders = (&ml_shaders::FULLSCREEN_VERT, lighting);
            let mut constants = shading.lighting_constants().to_vec();
            if samples {
                constants.push(shading.antialiasing.constant());
            }
            pass.lighting = pass.raster.pipeline(ctx, shaders, Draw::Screen, (pass.lighting_layout, 1), &constants)?;
            Ok(())
        })
    }
}

impl Pass for DeferredSubpasses {
    fn timer_name(&self) -> Option<&'static str> {
        Some("g-buffer + lighting")
    }

    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError> {
        self.raster.bind_frame(ctx, frame)?;
        self.lighting_sets.write(ctx, frame.slot, &|name| frame.resource(name))?;
        let t = frame.targets;
        let input =
            |view: vk::ImageView, layout| Some(Resource::Image(vk::DescriptorImageInfo::default().image_view(view).image_layout(layout)));
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        self.input_sets.write(ctx, frame.slot, &|name| match name {
            "depth_input" => input(t.depth.view, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL),
            _ => t.gbuffer_image(name.trim_end_matches("_input")).and_then(|g| input(g.view, read_only)),
        })
    }

    fn uses(&self) -> Vec<Use> {
        shading_reads(vk::PipelineStageFlags::FRAGMENT_SHADER)
    }

    fn record(&self, rec: &Recording) {
        self.raster.begin_and_draw_meshes(rec);
        let d = &rec.ctx.device;
        let sets = [self.lighting_sets.sets[rec.slot], rec.scene.textures.set, self.input_sets.sets[rec.slot]];
        // SAFETY: recording inside the render pass begun above; every handle is alive.
        unsafe {
            d.cmd_next_subpass(rec.cmd, vk::SubpassContents::INLINE);
            d.cmd_bind_pipeline(rec.cmd, vk::PipelineBindPoint::GRAPHICS, self.lighting);
            d.cmd_bind_descriptor_sets(rec.cmd, vk::PipelineBindPoint::GRAPHICS, self.lighting_layout, 0, &sets, &[]);
            d.cmd_draw(rec.cmd, 3, 1, 0, 0);
            d.cmd_end_render_pass(rec.cmd);
        }
    }

    fn destroy(&mut self, ctx: &Context) {
        ml_vk::shader::release_pipeline(ctx, self.lighting);
        self.lighting_sets.destroy(ctx);
        self.input_sets.destroy(ctx);
        self.raster.destroy(ctx);
    }
}

impl ml_vk::Release for DeferredSubpasses {
    fn release(&mut self, ctx: &Context) {
        Pass::destroy(self, ctx);
    }
}
