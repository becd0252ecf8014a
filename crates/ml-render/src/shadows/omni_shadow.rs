//! Point-light shadow cubes (docs/DESIGN.md#point-light-shadows), the GPU half: a cube-map array with six
//! depth layers per shadowed light, each texel the distance from the light to the nearest
//! surface over the light's radius (omni_shadow.frag), rendered every frame (the lights
//! move) before the shading passes, which read it through set 1 (omni_shadow.glsl).
//!
//! Five ways to fill it, one image: `copy` (the classic way: each face into one offscreen depth
//! target, then an image copy into the cube's layer), `direct` (each face straight into its
//! layer, a framebuffer per layer), and one pass per light for all six faces: `multiview`
//! (VK_KHR_multiview, view i = face i) or `layered` (instance i of a draw writes
//! gl_Layer = i; each object is drawn as the instances of the faces it reaches); or `compute`,
//! whose own pass (passes/omni_shadow_compute.rs) draws every face in compute shaders and
//! copies the depths in. Without
//! shadowed lights the array is a cleared 1×1 stand-in the shaders never sample.
//!
//! Alpha-masked objects are drawn in each pass after the others, by a pipeline of their own
//! whose fragment shader drops what their masks cut out (depth_pass.rs MaskedPipeline), made
//! with the others where the scene has a masked object (scenes without one never make it),
//! its set pointed at the scene's object buffer and alpha masks whenever those are made
//! (`bind_casters`).

use crate::depth_pass::{self, DepthPassDesc, MaskedPipeline, ShadowMaskPush};
use crate::error::RenderError;
use crate::gpu_mesh::{record_draws, SceneMeshes};
use crate::shadows::shadow_atlas::ShadowAtlasGpu;
use crate::shadows::shadow_settings::{OmniShadowMode, OmniShadowSettings};
use crate::sync::{Use, SHADOW_CUBES};
use glam::{Mat4, Vec3};
use ml_cpu::gpu_types::OmniShadowPush;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::omni_shadow::{face_view_proj, sphere_faces};
use ml_cpu::omni_shadow::{lights_in_view, shadowed_lights};
use ml_cpu::scene::{Object, Scene};
use ml_vk::image::{aspect_transition, full_range, StageAccessLayout};
use ml_vk::{shader, vk, Context, Image, ImageShape, VkError, VkResultExt};

/// The cube's depth format: 32-bit float, which holds distance / radius to 2⁻²⁴.
pub const CUBE_FORMAT: vk::Format = vk::Format::D32_SFLOAT;

/// Faces' near plane as a fraction of the light's radius (geometry nearer than this to the
/// light is clipped away; the stored depth is not the projection's, so this costs no
/// precision). The passes work in the light's frame measured in radii: far is 1.
pub const NEAR_FRACTION: f32 = 1e-3;

/// Where a shadowed light is this frame.
#[derive(Clone, Copy, Debug)]
pub struct ShadowedLight {
    pub position: Vec3,
    pub radius: f32,
}

pub struct OmniShadows {
    pub settings: Option<OmniShadowSettings>,
    /// The lights that cast shadows (scene indices; cube or atlas slot i: `chosen[i]`), and
    /// where they are in the frame being prepared.
    chosen: Vec<u32>,
    placed: Vec<ShadowedLight>,
    /// The shadow atlas (--omni-shadow atlas; stand-ins otherwise, and the cube array is).
    pub atlas: ShadowAtlasGpu,
    /// Six layers per shadowed light, viewed as a cube array (`cubes.view`).
    pub cubes: Image,
    /// The same layers as a 2D array (the shadow-cube debug view fetches texels).
    pub faces_view: vk::ImageView,
    /// copy: the one offscreen target every face is rendered into.
    offscreen: Image,
    /// direct: a 2D view per layer; multiview, layered: a 6-layer view per light.
    targets: Vec<vk::ImageView>,
    framebuffers: Vec<vk::Framebuffer>,
    render_pass: vk::RenderPass,
    layout: vk::PipelineLayout,
    pipeline: vk::Pipeline,
    /// Alpha-masked objects' pipeline (None: the scene has none).
    masked: Option<MaskedPipeline>,
    /// Whether to make it.
    has_masked: bool,
}

const DEPTH: vk::ImageAspectFlags = vk::ImageAspectFlags::DEPTH;
const SHADER_READERS: vk::PipelineStageFlags =
    vk::PipelineStageFlags::from_raw(vk::PipelineStageFlags::FRAGMENT_SHADER.as_raw() | vk::PipelineStageFlags::COMPUTE_SHADER.as_raw());

impl OmniShadows {
    /// The cubes for `settings` (None: the stand-in), with what renders them; `has_masked`:
    /// whether the scene has alpha-masked objects (they get a pipeline of their own).
    pub fn new(ctx: &Context, settings: Option<OmniShadowSettings>, has_masked: bool) -> Result<OmniShadows, RenderError> {
        let features = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT | vk::FormatFeatureFlags::SAMPLED_IMAGE;
        if !ctx.format_supports(CUBE_FORMAT, features) {
            return Err(VkError::Unsupported {
                device: ctx.info.name.clone(),
                what: "D32_SFLOAT depth images it renders and samples (point-light shadow cubes)".into(),
            }
            .into());
        }
        let shadows = OmniShadows {
            settings,
            chosen: Vec::new(),
            placed: Vec::new(),
            atlas: ShadowAtlasGpu::new(ctx, settings)?,
            cubes: Image::null(),
            faces_view: vk::ImageView::null(),
            offscreen: Image::null(),
            targets: Vec::new(),
            framebuffers: Vec::new(),
            render_pass: vk::RenderPass::null(),
            layout: vk::PipelineLayout::null(),
            pipeline: vk::Pipeline::null(),
            masked: None,
            has_masked,
        };
        Ok(ml_vk::build(ctx, shadows, |s| s.create(ctx))?)
    }

    /// Choose the lights that cast shadows (`--shadowed-lights`: the strongest as seen from
    /// the camera, or all that reach the view of an `aspect` image).
    pub fn choose(&mut self, scene: &Scene, aspect: f32) {
        self.chosen = match self.settings {
            None => Vec::new(),
            Some(o) if o.all && o.rays() => (0..scene.lights.len() as u32).collect(),
            Some(o) if o.all => lights_in_view(&scene.lights, &scene.camera, aspect, scene.light_motion, o.lights as usize),
            Some(o) => shadowed_lights(&scene.lights, o.lights as usize, scene.camera.position),
        };
    }

    /// Mark the chosen lights in `lights` (the scene's, as the GPU is to read them) with
    /// their shadow slots: `PointLight::color[3] = slot + 1`, which the shading passes read.
    /// The scene's own lights stay as they were loaded.
    pub fn mark(&self, lights: &mut [PointLight]) {
        for (slot, &i) in self.chosen.iter().enumerate() {
            lights[i as usize].color[3] = (slot + 1) as f32;
        }
    }

    /// Place the chosen lights for a frame: `lights` at rest moved by the animation's
    /// `offset` (the same sum the light buffer holds, on the CPU or the GPU).
    pub fn place(&mut self, lights: &[PointLight], offset: Vec3) {
        if self.settings.is_some_and(|o| o.rays()) {
            // Shadow rays aim at the lights where the GPU has them; nothing reads these.
            return;
        }
        self.placed = self
            .chosen
            .iter()
            .map(|&i| {
                let p = lights[i as usize].position_radius;
                ShadowedLight { position: Vec3::new(p[0] + offset.x, p[1] + offset.y, p[2] + offset.z), radius: p[3] }
            })
            .collect();
    }

    /// The chosen lights' scene indices, slot order.
    pub fn chosen(&self) -> &[u32] {
        &self.chosen
    }

    /// Where the chosen lights are in the frame being prepared (slot order).
    pub fn placed(&self) -> &[ShadowedLight] {
        &self.placed
    }

    fn create(&mut self, ctx: &Context) -> Result<(), VkError> {
        let (cubes, size) = self.cube_settings().map_or((1, 1), |s| (s.lights, s.size));
        let layers = cubes * 6;
        let shape =
            ImageShape { extent: vk::Extent2D { width: size, height: size }, levels: 1, layers, view: vk::ImageViewType::CUBE_ARRAY };
        // The shaders read it in DEPTH_STENCIL_READ_ONLY_OPTIMAL, which needs the attachment
        // usage even where only copies (or the stand-in's clear) write it.
        // (Transfer source: `read_depths`.)
        let usage = vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        self.cubes = Image::new(ctx, "shadow cubes", shape, CUBE_FORMAT, usage, DEPTH)?;
        self.faces_view = self.cubes.view_of(ctx, vk::ImageViewType::TYPE_2D_ARRAY, 0..layers, DEPTH)?;
        let Some(settings) = self.cube_settings() else {
            return clear_stand_in(ctx, &self.cubes);
        };
        if matches!(settings.mode, OmniShadowMode::Compute { .. }) {
            // Its own pass draws the cubes and copies them in (passes/omni_shadow_compute.rs).
            return Ok(());
        }
        let readers = (SHADER_READERS, vk::AccessFlags::SHADER_READ);
        // Each pass clears its target, so it waits for whoever read that target last: the
        // previous frame's shading (direct, multiview) or this frame's previous copy (copy).
        let (final_layout, after, readers) = match settings.mode {
            OmniShadowMode::Copy => (
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                vk::PipelineStageFlags::TRANSFER,
                (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_READ),
            ),
            _ => (vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL, SHADER_READERS, readers),
        };
        let multiview = settings.mode == OmniShadowMode::Multiview;
        let view_mask = if multiview { 0b11_1111 } else { 0 };
        self.render_pass = depth_pass::render_pass(ctx, &DepthPassDesc { format: CUBE_FORMAT, final_layout, after, readers, view_mask })?;
        let push = [vk::PushConstantRange::default().stage_flags(vk::ShaderStageFlags::VERTEX).size(size_of::<OmniShadowPush>() as u32)];
        self.layout = shader::pipeline_layout(ctx, &[], &push)?;
        let vertex = match settings.mode {
            OmniShadowMode::Multiview => ml_shaders::OMNI_SHADOW_MULTIVIEW_VERT.spirv,
            OmniShadowMode::Layered => ml_shaders::OMNI_SHADOW_LAYERED_VERT.spirv,
            _ => ml_shaders::OMNI_SHADOW_VERT.spirv,
        };
        self.pipeline = depth_pass::pipeline(ctx, self.render_pass, self.layout, (vertex, Some(ml_shaders::OMNI_SHADOW_FRAG.spirv)))?;
        if self.has_masked {
            let vertex = match settings.mode {
                OmniShadowMode::Multiview => &ml_shaders::OMNI_SHADOW_MULTIVIEW_MASKED_VERT,
                OmniShadowMode::Layered => &ml_shaders::OMNI_SHADOW_LAYERED_MASKED_VERT,
                _ => &ml_shaders::OMNI_SHADOW_MASKED_VERT,
            };
            let shaders = (vertex, &ml_shaders::OMNI_SHADOW_MASKED_FRAG);
            // One set: it points at the scene's buffers, which change only between frames.
            self.masked = Some(MaskedPipeline::new(ctx, self.render_pass, shaders, 1)?);
        }
        let extent = shape.extent;
        match settings.mode {
            OmniShadowMode::Copy => {
                let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC;
                self.offscreen = Image::new_2d(ctx, "shadow face", extent, CUBE_FORMAT, usage, DEPTH)?;
                let view = self.offscreen.view;
                self.add_framebuffer(ctx, view, (size, 1))?;
            }
            OmniShadowMode::Direct => {
                for layer in 0..layers {
                    let view = self.cubes.view_of(ctx, vk::ImageViewType::TYPE_2D, layer..layer + 1, DEPTH)?;
                    self.targets.push(view);
                    self.add_framebuffer(ctx, view, (size, 1))?;
                }
            }
            OmniShadowMode::Multiview | OmniShadowMode::Layered => {
                // Multiview: one layer of framebuffer, the view mask spreads it over six;
                // layered: six framebuffer layers the shader picks from.
                for cube in 0..cubes {
                    let view = self.cubes.view_of(ctx, vk::ImageViewType::TYPE_2D_ARRAY, cube * 6..cube * 6 + 6, DEPTH)?;
                    self.targets.push(view);
                    let layers = if multiview { 1 } else { 6 };
                    self.add_framebuffer(ctx, view, (size, layers))?;
                }
            }
            OmniShadowMode::Compute { .. } | OmniShadowMode::Atlas(_) | OmniShadowMode::Rays => {}
        }
        Ok(())
    }

    fn add_framebuffer(&mut self, ctx: &Context, view: vk::ImageView, (size, layers): (u32, u32)) -> Result<(), VkError> {
        let views = [view];
        let info =
            vk::FramebufferCreateInfo::default().render_pass(self.render_pass).attachments(&views).width(size).height(size).layers(layers);
        // SAFETY: valid device; the view matches the render pass's attachment.
        let framebuffer = unsafe { ctx.device.create_framebuffer(&info, None) }.ctx("vkCreateFramebuffer")?;
        self.framebuffers.push(framebuffer);
        Ok(())
    }

    /// The settings where the shadows are in the cube array (not the atlas).
    fn cube_settings(&self) -> Option<OmniShadowSettings> {
        self.settings.filter(|s| s.atlas().is_none() && !s.rays())
    }

    /// What a frame's cube drawing by the graphics modes does to the cube array (`sync`):
    /// copy overwrites it by transfers and leaves it TRANSFER_DST_OPTIMAL; direct, multiview
    /// and layered render into it, ordered by their render passes' external dependencies
    /// (after the shaders that read it last; their writes visible to shaders, left
    /// DEPTH_STENCIL_READ_ONLY_OPTIMAL). None where no graphics mode draws it.
    pub fn cube_use(&self) -> Option<Use> {
        let settings = self.cube_settings()?;
        match settings.mode {
            OmniShadowMode::Compute { .. } | OmniShadowMode::Atlas(_) | OmniShadowMode::Rays => None,
            OmniShadowMode::Copy => Some(Use::overwriting(SHADOW_CUBES, (TRANSFER_DST.0, TRANSFER_DST.1), TRANSFER_DST.2)),
            OmniShadowMode::Direct | OmniShadowMode::Multiview | OmniShadowMode::Layered => {
                Some(Use::redrawn_for_readers(SHADOW_CUBES, SHADER_READERS))
            }
        }
    }

    /// The layout the cube array is in before the first frame: the stand-in's, cleared when
    /// it was made; None (undefined) where the frames draw it.
    pub fn initial_cube_layout(&self) -> Option<vk::ImageLayout> {
        self.cube_settings().is_none().then_some(vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL)
    }

    /// One texel of a face in face units (FrameUniforms::omni_texel).
    pub fn texel(&self) -> f32 {
        2.0 / self.cubes.extent.width as f32
    }

    /// Point the masked objects' pipeline (if any) at the scene's object buffer and alpha
    /// masks (no frame in flight).
    pub fn bind_casters(&self, ctx: &Context, buffers: (vk::Buffer, vk::Buffer)) -> Result<(), VkError> {
        self.masked.as_ref().map_or(Ok(()), |m| m.bind(ctx, 0, buffers))
    }

    /// Render every cube: `lights[i]` into cube i, the objects that reach into its sphere.
    /// The cube array as `cube_use` declares it: copy takes it in TRANSFER_DST_OPTIMAL and
    /// leaves it so; the other modes' render passes order it themselves.
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer, lights: &[ShadowedLight], (meshes, objects): (&SceneMeshes, &[Object])) {
        let Some(settings) = self.cube_settings().filter(|s| !matches!(s.mode, OmniShadowMode::Compute { .. })) else { return };
        let masked_pipeline = self.masked.as_ref();
        // Which objects the masked pipeline draws (none without it).
        let is_masked: Vec<bool> = objects.iter().map(|o| masked_pipeline.is_some() && o.extras.masked()).collect();
        let d = &ctx.device;
        let size = settings.size;
        let copy = settings.mode == OmniShadowMode::Copy;
        for (cube, light) in lights.iter().enumerate().take(settings.lights as usize) {
            // Objects are drawn into the faces their bounding sphere reaches (none when it
            // misses the light's sphere): per object, once per light.
            let faces: Vec<u32> = objects
                .iter()
                .map(|o| {
                    let (centre, bound) = o.bounding_sphere();
                    if centre.distance(light.position) > light.radius + bound {
                        return 0;
                    }
                    sphere_faces(centre - light.position, bound)
                })
                .collect();
            let world_to_light = Mat4::from_scale(Vec3::splat(1.0 / light.radius)) * Mat4::from_translation(-light.position);
            let one_pass = matches!(settings.mode, OmniShadowMode::Multiview | OmniShadowMode::Layered);
            let passes: Vec<(Option<u32>, Mat4)> = if one_pass {
                vec![(None, Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, NEAR_FRACTION, 1.0))]
            } else {
                (0..6).map(|face| (Some(face), face_view_proj(Vec3::ZERO, face, NEAR_FRACTION, 1.0))).collect()
            };

            for (face, view_proj) in passes {
                let framebuffer = match (settings.mode, face) {
                    (OmniShadowMode::Copy, _) => self.framebuffers[0],
                    (OmniShadowMode::Direct, Some(f)) => self.framebuffers[cube * 6 + f as usize],
                    _ => self.framebuffers[cube],
                };
                let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: vk::Extent2D { width: size, height: size } };
                let begin = vk::RenderPassBeginInfo::default()
                    .render_pass(self.render_pass)
                    .framebuffer(framebuffer)
                    .render_area(area)
                    .clear_values(&depth_pass::CLEAR_FAR);
                // SAFETY: recording state; every handle lives as long as this object, which
                // outlives the frames that use it.
                unsafe {
                    d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.pipeline);
                    depth_pass::set_square_viewport(ctx, cmd, size);
                    // Per-face passes draw an object if it reaches their face; layered draws
                    // instance i (face i) of each face it reaches; multiview draws every view.
                    let instances = |i: u32| match (settings.mode, face) {
                        (OmniShadowMode::Layered, _) => faces[i as usize],
                        (OmniShadowMode::Multiview, _) => u32::from(faces[i as usize] != 0),
                        (_, Some(f)) => (faces[i as usize] >> f) & 1,
                        (_, None) => 0,
                    };
                    let opaque = |i: u32| if is_masked[i as usize] { 0 } else { instances(i) };
                    record_draws(ctx, cmd, (meshes, objects), opaque, |_, object| {
                        let push = OmniShadowPush {
                            view_proj: view_proj.to_cols_array_2d(),
                            model_to_light: (world_to_light * object.transform).to_cols_array_2d(),
                        };
                        d.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::VERTEX, 0, bytemuck::bytes_of(&push));
                    });
                    // Then the masked objects that reach this pass's faces, by their pipeline.
                    let cut = |i: u32| if is_masked[i as usize] { instances(i) } else { 0 };
                    if let Some(m) = masked_pipeline.filter(|_| (0..objects.len() as u32).any(|i| cut(i) != 0)) {
                        m.record_bind(ctx, cmd, 0);
                        record_draws(ctx, cmd, (meshes, objects), cut, |i, object| {
                            m.push(ctx, cmd, &ShadowMaskPush::new(view_proj, world_to_light * object.transform, i));
                        });
                    }
                    d.cmd_end_render_pass(cmd);
                }
                if let (true, Some(f)) = (copy, face) {
                    self.copy_face(ctx, cmd, cube as u32 * 6 + f);
                }
            }
        }
    }

    /// The copy mode's step: the offscreen face (left TRANSFER_SRC_OPTIMAL by the pass, whose
    /// outgoing dependency orders this copy after its depth writes) into cube layer `layer`.
    fn copy_face(&self, ctx: &Context, cmd: vk::CommandBuffer, layer: u32) {
        let subresource = |base: u32| vk::ImageSubresourceLayers::default().aspect_mask(DEPTH).base_array_layer(base).layer_count(1);
        let size = self.offscreen.extent;
        let region = [vk::ImageCopy::default().src_subresource(subresource(0)).dst_subresource(subresource(layer)).extent(vk::Extent3D {
            width: size.width,
            height: size.height,
            depth: 1,
        })];
        // SAFETY: recording state outside a render pass; both images are alive, in the
        // layouts named, and the region lies within both.
        unsafe {
            ctx.device.cmd_copy_image(
                cmd,
                self.offscreen.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                self.cubes.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &region,
            )
        };
    }

    /// Every texel of every layer as the last frame left it (layer after layer, row by row),
    /// copied to the host; for tests and tools, not the frame loop (it waits for the GPU).
    pub fn read_depths(&self, ctx: &Context) -> Result<Vec<f32>, VkError> {
        read_depth_layers(ctx, &self.cubes, self.cube_settings().map_or(1, |s| s.lights) * 6)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: the device is idle (the caller's contract); null handles are ignored.
        unsafe {
            for f in self.framebuffers.drain(..) {
                ctx.device.destroy_framebuffer(f, None);
            }
            for v in self.targets.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
            ctx.device.destroy_image_view(self.faces_view, None);
            ml_vk::shader::release_pipeline(ctx, self.pipeline);
        }
        if let Some(mut m) = self.masked.take() {
            m.destroy(ctx);
        }
        self.faces_view = vk::ImageView::null();
        self.pipeline = vk::Pipeline::null();
        self.layout = vk::PipelineLayout::null();
        self.render_pass = vk::RenderPass::null();
        self.offscreen.destroy(ctx);
        self.cubes.destroy(ctx);
        self.atlas.destroy(ctx);
    }
}

impl ml_vk::Release for OmniShadows {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

const TRANSFER_DST: StageAccessLayout =
    (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);

/// The first `layers` layers of a sampled 32-bit depth image (layer after layer, row by row),
/// copied to the host; for tests and tools (it waits for the GPU).
pub(crate) fn read_depth_layers(ctx: &Context, image: &Image, layers: u32) -> Result<Vec<f32>, VkError> {
    let extent = image.extent;
    let bytes = extent.width as u64 * extent.height as u64 * layers as u64 * 4;
    let mut host =
        ml_vk::Buffer::new(ctx, "depth read-back", bytes, vk::BufferUsageFlags::TRANSFER_DST, gpu_allocator::MemoryLocation::GpuToCpu)?;
    let sampled = (SHADER_READERS, vk::AccessFlags::SHADER_READ, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL);
    let source = (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_READ, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
    let copied = ml_vk::commands::one_shot(ctx, |cmd| {
        transition(ctx, cmd, image.raw, sampled, source);
        let subresource = vk::ImageSubresourceLayers::default().aspect_mask(DEPTH).layer_count(layers);
        let region = [vk::BufferImageCopy::default().image_subresource(subresource).image_extent(vk::Extent3D {
            width: extent.width,
            height: extent.height,
            depth: 1,
        })];
        // SAFETY: recording state; the image is in TRANSFER_SRC_OPTIMAL and the buffer holds
        // every layer.
        unsafe { ctx.device.cmd_copy_image_to_buffer(cmd, image.raw, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, host.raw, &region) };
        transition(ctx, cmd, image.raw, source, sampled);
        ml_vk::commands::transfer_to_host_barrier(ctx, cmd);
    });
    let depths = copied.map(|()| bytemuck::pod_collect_to_vec(host.mapped()));
    host.destroy(ctx);
    depths
}

/// A layout transition of every layer of a depth image.
fn transition(ctx: &Context, cmd: vk::CommandBuffer, image: vk::Image, from: StageAccessLayout, to: StageAccessLayout) {
    aspect_transition(ctx, cmd, (image, DEPTH), from, to);
}

/// The stand-in: every layer cleared to 1.0 (nothing in reach), left as the shaders expect.
fn clear_stand_in(ctx: &Context, cubes: &Image) -> Result<(), VkError> {
    ml_vk::commands::one_shot(ctx, |cmd| {
        transition(
            ctx,
            cmd,
            cubes.raw,
            (vk::PipelineStageFlags::TOP_OF_PIPE, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED),
            TRANSFER_DST,
        );
        let clear = vk::ClearDepthStencilValue { depth: 1.0, stencil: 0 };
        // SAFETY: recording state; the image is in TRANSFER_DST_OPTIMAL.
        unsafe {
            ctx.device.cmd_clear_depth_stencil_image(cmd, cubes.raw, vk::ImageLayout::TRANSFER_DST_OPTIMAL, &clear, &[full_range(DEPTH)])
        };
        transition(
            ctx,
            cmd,
            cubes.raw,
            TRANSFER_DST,
            (SHADER_READERS, vk::AccessFlags::SHADER_READ, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL),
        );
    })
}
