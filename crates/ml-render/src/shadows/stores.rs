//! The shadow stores behind one interface: the point lights' cube array and shadow atlas
//! (omni_shadow.rs, shadow_atlas.rs), the sun's map (sun_shadow.rs) and the shadow rays'
//! hierarchy of the scene's objects (ray_geometry.rs). Made with the scene's GPU resources;
//! their images and the atlas are bound in the scene's set 1 by the names the shaders give them
//! (`resource`), the rays' buffers are named in every frame's table (`named_buffers`). The
//! renderer owns them; the shadow passes share them (`SharedShadows`).

use crate::descriptors::Resource;
use crate::error::RenderError;
use crate::report::FrameStats;
use crate::scene::SceneGpu;
use crate::scene_part::{FrameCounts, ScenePart};
use crate::shadows::omni_shadow::{self, OmniShadows};
use crate::shadows::ray_geometry::RayGeometry;
use crate::shadows::shadow_settings::{OmniShadowSettings, SunShadowMode};
use crate::shadows::sun_map::clear_shadow_map;
use crate::sync::{BufferName, ImageName, SHADOW_CUBES, SUN_MAP};
use ml_cpu::blinn_phong::shadow_view_proj;
use ml_cpu::gpu_types::FrameUniforms;
use ml_cpu::scene::Scene;
use ml_vk::image::sampler;
use ml_vk::{vk, Context, Image, VkError};
use std::cell::RefCell;
use std::rc::Rc;

/// Texels per side of the sun's shadow map (blinn-phong).
pub const SHADOW_MAP_SIZE: u32 = 2048;

/// What the stores are made for (the render settings' `shadow_config`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowConfig {
    /// Whether the sun's shadow map is drawn (blinn-phong), and by whom.
    pub sun: Option<SunShadowMode>,
    /// Point-light shadows (None: the stand-in).
    pub omni: Option<OmniShadowSettings>,
}

pub struct ShadowStores {
    /// Point-light shadow cubes or the atlas (a stand-in without shadowed lights), rendered
    /// each frame by the point-light shadow passes.
    pub omni: OmniShadows,
    /// The sun's shadow map (blinn-phong; a 1×1 texel at the far plane otherwise), drawn by
    /// the sun's shadow pass when the casters change.
    sun_map: Image,
    /// Texels per side of the sun's map.
    pub sun_map_size: u32,
    /// The sun's map compared (3×3 PCF taps), the point lights' cubes compared, and either
    /// read as plain depths (the shadow debug views).
    samplers: Vec<vk::Sampler>,
    /// The sun's shadow-map view-projection (blinn-phong).
    pub sun_view_proj: glam::Mat4,
    /// How long the sun's shadow rays are: from any point of the scene's box beyond it.
    pub sun_ray_length: f32,
    /// Whether the sun's shadow map is drawn, and by whom.
    sun: Option<SunShadowMode>,
    /// The casters changed since the sun's map was drawn: the next frame's sun shadow pass
    /// draws it.
    pub sun_due: bool,
    /// The shadow rays' hierarchy of the objects (stand-ins where no light casts rays).
    pub rays: RayGeometry,
    wants_rays: bool,
}

/// The stores as the renderer and the shadow passes share them.
pub type SharedShadows = Rc<RefCell<ShadowStores>>;

impl ShadowStores {
    /// The stores for `scene` as `config` asks, the sun's map in `sun_format` (which must be
    /// sampleable), cleared; `casters_changed` once the scene's objects are on the GPU.
    pub fn new(ctx: &Context, scene: &Scene, config: ShadowConfig, sun_format: vk::Format) -> Result<ShadowStores, RenderError> {
        let has_masked = scene.objects.iter().any(|o| o.extras.masked());
        let stores = ShadowStores {
            omni: OmniShadows::new(ctx, config.omni, has_masked)?,
            sun_map: Image::null(),
            sun_map_size: if config.sun.is_some() { SHADOW_MAP_SIZE } else { 1 },
            samplers: Vec::new(),
            sun_view_proj: glam::Mat4::IDENTITY,
            sun_ray_length: 1.0,
            sun: config.sun,
            sun_due: false,
            rays: RayGeometry::null(),
            // Directional lights cast their shadows by rays in every point-light shadow mode.
            wants_rays: config.omni.is_some_and(|o| o.rays() || !scene.directional.is_empty()) || config.sun == Some(SunShadowMode::Rays),
        };
        Ok(ml_vk::build(ctx, stores, |s| s.create(ctx, sun_format))?)
    }

    fn create(&mut self, ctx: &Context, format: vk::Format) -> Result<(), VkError> {
        let extent = vk::Extent2D { width: self.sun_map_size, height: self.sun_map_size };
        // Drawn by a render pass, or copied from the compute raster's buffer; read back by tests.
        let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        self.sun_map = Image::new_2d(ctx, "shadow map", extent, format, usage, vk::ImageAspectFlags::DEPTH)?;
        // Cleared to the far plane ("lit everywhere") until the objects are drawn into it.
        clear_shadow_map(ctx, &self.sun_map)?;
        // Outside the map is lit: the border is the far plane (1.0) and the test is ≤. Each
        // tap filters four comparisons bilinearly (as the seed's DX12-book sampler does), so
        // the lit fraction changes continuously with the position: a position rebuilt from
        // depth (deferred) then moves it by as little as the position moved, where a nearest
        // tap would jump by a ninth of the sun across a texel boundary.
        let compare = Some(vk::CompareOp::LESS_OR_EQUAL);
        self.samplers.push(sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_BORDER, depth_filter(ctx, format), compare)?);
        // The point-light cubes compare the same way (cube sampling never leaves the cube).
        let omni_filter = depth_filter(ctx, omni_shadow::CUBE_FORMAT);
        self.samplers.push(sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, omni_filter, compare)?);
        // The sun's map read as plain depths (the shadow-map debug view), the cubes' faces too.
        self.samplers.push(sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, vk::Filter::NEAREST, None)?);
        Ok(())
    }

    /// The casters changed (the scene's objects reached the GPU, or were replaced; no frame in
    /// flight): the compute rasters' object buffers, the rays' hierarchy, the sun's view (its
    /// map is due: the next frame draws it, where the sun casts a map).
    pub fn casters_changed(&mut self, ctx: &Context, scene: &Scene, gpu: &SceneGpu) -> Result<(), RenderError> {
        self.omni.bind_casters(ctx, (gpu.objects.raw, gpu.alpha_masks.raw))?;
        self.rays.destroy(ctx);
        self.rays = RayGeometry::new(ctx, scene, self.wants_rays)?;
        let (lo, hi) = scene.bounds();
        self.sun_view_proj = shadow_view_proj(lo, hi, scene.blinn_phong.sun_direction);
        self.sun_ray_length = (hi - lo).length() + 1.0;
        self.sun_due = self.sun.is_some_and(|mode| mode != SunShadowMode::Rays);
        Ok(())
    }

    /// The sun's map (the sun's shadow pass draws into it).
    pub fn sun_map(&self) -> &Image {
        &self.sun_map
    }

    /// The sun's shadow map's texels (row by row), copied to the host; for tests and tools.
    pub fn read_sun_map(&self, ctx: &Context) -> Result<Vec<f32>, VkError> {
        omni_shadow::read_depth_layers(ctx, &self.sun_map, 1)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.omni.destroy(ctx);
        self.rays.destroy(ctx);
        self.sun_map.destroy(ctx);
        // SAFETY: the device is idle (the caller's contract); null handles are ignored.
        unsafe {
            for s in self.samplers.drain(..) {
                ctx.device.destroy_sampler(s, None);
            }
        }
    }
}

impl ScenePart for ShadowStores {
    /// Fill the frame's uniforms the stores own: the sun's view-projection, its map's texel
    /// (`sun_direction.w`: in map units; `sun_strength.w`: in the world — the orthographic
    /// projection's first row is the sun's x axis over the half-width it covers), its rays'
    /// length, and a point-light cube texel.
    fn frame_uniforms(&self, u: &mut FrameUniforms) {
        let size = self.sun_map_size as f32;
        u.shadow_view_proj = self.sun_view_proj.to_cols_array_2d();
        u.sun_direction[3] = 1.0 / size;
        u.sun_strength[3] = 2.0 / self.sun_view_proj.row(0).truncate().length() / size;
        u.shadow_rays[0] = self.sun_ray_length;
        u.omni_texel = self.omni.texel();
    }

    /// What the stores bind in the scene's set 1 (common/textures.glsl), by name.
    fn resource(&self, name: &str) -> Option<Resource> {
        let [sun_compare, omni_compare, plain] = self.samplers[..] else { return None };
        let depth_read = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
        let info = |sampler: vk::Sampler, view: vk::ImageView| {
            Resource::Image(vk::DescriptorImageInfo::default().sampler(sampler).image_view(view).image_layout(depth_read))
        };
        Some(match name {
            "shadow_map" => info(sun_compare, self.sun_map.view),
            "shadow_depth" => info(plain, self.sun_map.view),
            "omni_shadows" => info(omni_compare, self.omni.cubes.view),
            "omni_faces" => info(plain, self.omni.faces_view),
            "ShadowAtlasBuffer" => Resource::Buffer(self.omni.atlas.depths.raw),
            "ShadowAtlasTileBuffer" => Resource::Buffer(self.omni.atlas.tiles.raw),
            _ => return None,
        })
    }

    /// The stores' buffers shaders bind from the frame's table (the rays' hierarchy).
    fn named_buffers(&self) -> Vec<(BufferName, vk::Buffer)> {
        self.rays.named_buffers().to_vec()
    }

    /// The rays' hierarchy's row, with the rays the last frame traced where they were counted.
    fn report(&self, counts: &FrameCounts, stats: &mut FrameStats) {
        if let Some(mut rays) = self.rays.stats {
            rays.traced = counts.rays_traced;
            stats.set_feature(rays);
        }
    }

    /// The stores' images that passes declare (`sync`), under their names: the sun's map and
    /// the shadow cubes.
    fn named_image(&self, name: ImageName) -> Option<(vk::Image, vk::ImageAspectFlags)> {
        let image = match name {
            SUN_MAP => &self.sun_map,
            SHADOW_CUBES => &self.omni.cubes,
            _ => return None,
        };
        Some((image.raw, vk::ImageAspectFlags::DEPTH))
    }
}

impl ml_vk::Release for ShadowStores {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// LINEAR where the format filters (each tap then blends four comparisons), else NEAREST.
fn depth_filter(ctx: &Context, format: vk::Format) -> vk::Filter {
    if ctx.format_supports(format, vk::FormatFeatureFlags::SAMPLED_IMAGE_FILTER_LINEAR) {
        vk::Filter::LINEAR
    } else {
        vk::Filter::NEAREST
    }
}
