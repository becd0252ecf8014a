//! Set 1 of every shading pipeline: the scene's textures. For the blinn-phong model the sun's
//! shadow map (drawn by sun_shadow.rs), a sky cubemap for reflections, the albedo and normal
//! maps (all made by our code: ml_cpu::textures); the seed model binds 1×1 stand-ins it never
//! samples. The environment light's maps (crate::environment) join the set. The layout is
//! textures.glsl's and environment.glsl's set 1, as reflected from the shaders.

use crate::descriptors::{self, Resource, SetLayout};
use crate::environment::EnvironmentMaps;
use crate::error::RenderError;
use crate::scene::omni_shadow::{self, OmniShadows};
use crate::scene::sun_shadow::{draw_shadow_map, render_shadow_map, ShadowInputs};
use ml_cpu::textures;
use ml_vk::descriptors::allocate_set;
use ml_vk::image::{sampler, texture_with, ImageShape};
use ml_vk::{vk, Context, Image, VkError};

/// Texels per side of the sun's shadow map (blinn-phong).
pub const SHADOW_MAP_SIZE: u32 = 2048;
const MATERIAL_MAP_SIZE: u32 = 256;
const SKY_SIZE: u32 = 64;

pub struct SceneTextures {
    pub set_layout: SetLayout,
    pub set: vk::DescriptorSet,
    pool: vk::DescriptorPool,
    images: Vec<Image>,
    samplers: Vec<vk::Sampler>,
    /// Texels per side of the shadow map (1 for the seed model).
    pub shadow_size: u32,
}

/// Places in `SceneTextures::images` (the order `create` makes them in).
const ALBEDO_IMAGE: usize = 0;
const NORMAL_IMAGE: usize = 1;
const SKY_IMAGE: usize = 2;
const SHADOW_IMAGE: usize = 3;

impl SceneTextures {
    /// The textures: with `blinn_phong` the real maps and a shadow map (cleared: fill it with
    /// `render_shadow_map` once the meshes are on the GPU), else 1×1 stand-ins. The shadow map
    /// uses `depth_format`, which must be sampleable. `omni` holds the point-light shadow cubes.
    pub fn new(
        ctx: &Context,
        blinn_phong: bool,
        depth_format: vk::Format,
        (omni, environment): (&OmniShadows, &EnvironmentMaps),
    ) -> Result<SceneTextures, VkError> {
        let t = SceneTextures {
            set_layout: SetLayout::null(),
            set: vk::DescriptorSet::null(),
            pool: vk::DescriptorPool::null(),
            images: Vec::new(),
            samplers: Vec::new(),
            shadow_size: 1,
        };
        ml_vk::build(ctx, t, |t| t.create(ctx, blinn_phong, depth_format, (omni, environment)))
    }

    /// Draw every object of `inputs` into the shadow map, from the sun; its GPU milliseconds
    /// (None without timestamps).
    pub fn render_shadow_map(&self, ctx: &Context, inputs: &ShadowInputs) -> Result<Option<f64>, RenderError> {
        draw_shadow_map(ctx, &self.images[SHADOW_IMAGE], inputs)
    }

    /// The sun's shadow map's texels (row by row), copied to the host; for tests and tools.
    pub fn read_shadow_map(&self, ctx: &Context) -> Result<Vec<f32>, VkError> {
        omni_shadow::read_depth_layers(ctx, &self.images[SHADOW_IMAGE], 1)
    }

    fn create(
        &mut self,
        ctx: &Context,
        real: bool,
        depth_format: vk::Format,
        (omni, environment): (&OmniShadows, &EnvironmentMaps),
    ) -> Result<(), VkError> {
        // Read by the fragment shaders and the compute lighting pass: textures.glsl's set 1.
        let stages = [
            (&ml_shaders::FORWARD_FRAG, vk::ShaderStageFlags::FRAGMENT),
            (&ml_shaders::DEFERRED_LIGHTING_COMP, vk::ShaderStageFlags::COMPUTE),
        ];
        self.set_layout = SetLayout::new(ctx, &stages, 1)?;
        self.pool = descriptors::pool(ctx, &[(&self.set_layout, 1)])?;
        self.set = allocate_set(ctx, self.pool, self.set_layout.raw)?;

        let rgba = vk::Format::R8G8B8A8_UNORM;
        let flat = |size: u32| ImageShape {
            extent: vk::Extent2D { width: size, height: size },
            levels: 1,
            layers: 1,
            view: vk::ImageViewType::TYPE_2D,
        };
        if real {
            // A mip chain as texture_with takes it: per level, its one layer.
            let mipmapped = |name: &str, m: &textures::MipChain| {
                let levels: Vec<Vec<&[u8]>> = m.levels.iter().map(|l| vec![l.as_slice()]).collect();
                texture_with(ctx, name, ImageShape { levels: m.levels.len() as u32, ..flat(m.size) }, rgba, &levels)
            };
            self.images.push(mipmapped("albedo map", &textures::tiles_albedo(MATERIAL_MAP_SIZE))?);
            self.images.push(mipmapped("normal map", &textures::bumps_normal_map(MATERIAL_MAP_SIZE))?);
            let sky = textures::sky_cube(SKY_SIZE);
            let cube = ImageShape { view: vk::ImageViewType::CUBE, layers: 6, ..flat(SKY_SIZE) };
            self.images.push(texture_with(ctx, "sky", cube, rgba, &[sky.iter().map(|f| f.as_slice()).collect()])?);
        } else {
            let white = [255u8; 4];
            let up = [128u8, 128, 255, 255];
            self.images.push(texture_with(ctx, "albedo map", flat(1), rgba, &[vec![&white[..]]])?);
            self.images.push(texture_with(ctx, "normal map", flat(1), rgba, &[vec![&up[..]]])?);
            let cube = ImageShape { view: vk::ImageViewType::CUBE, layers: 6, ..flat(1) };
            self.images.push(texture_with(ctx, "sky", cube, rgba, &[vec![&white[..]; 6]])?);
        }
        self.shadow_size = if real { SHADOW_MAP_SIZE } else { 1 };
        let extent = vk::Extent2D { width: self.shadow_size, height: self.shadow_size };
        // Drawn by a render pass, or copied from the compute raster's buffer; read back by tests.
        let usage = vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT
            | vk::ImageUsageFlags::SAMPLED
            | vk::ImageUsageFlags::TRANSFER_DST
            | vk::ImageUsageFlags::TRANSFER_SRC;
        self.images.push(Image::new_2d(ctx, "shadow map", extent, depth_format, usage, vk::ImageAspectFlags::DEPTH)?);
        // Cleared to the far plane ("lit everywhere") until the objects are drawn into it.
        render_shadow_map(ctx, &self.images[SHADOW_IMAGE], None)?;

        let material_sampler = sampler(ctx, vk::SamplerAddressMode::REPEAT, vk::Filter::LINEAR, None)?;
        self.samplers.push(material_sampler);
        let sky_sampler = sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, vk::Filter::LINEAR, None)?;
        self.samplers.push(sky_sampler);
        // Outside the map is lit: the border is the far plane (1.0) and the test is ≤. Each
        // tap filters four comparisons bilinearly (as the seed's DX12-book sampler does), so
        // the lit fraction changes continuously with the position: a position rebuilt from
        // depth (deferred) then moves it by as little as the position moved, where a nearest
        // tap would jump by a ninth of the sun across a texel boundary.
        let shadow_sampler =
            sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_BORDER, depth_filter(ctx, depth_format), Some(vk::CompareOp::LESS_OR_EQUAL))?;
        self.samplers.push(shadow_sampler);
        // The point-light cubes compare the same way (cube sampling never leaves the cube).
        let omni_filter = depth_filter(ctx, omni_shadow::CUBE_FORMAT);
        let omni_sampler = sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, omni_filter, Some(vk::CompareOp::LESS_OR_EQUAL))?;
        self.samplers.push(omni_sampler);
        let info = |sampler: vk::Sampler, image: &Image, layout: vk::ImageLayout| {
            vk::DescriptorImageInfo::default().sampler(sampler).image_view(image.view).image_layout(layout)
        };
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let depth_read = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
        // The shadow map read as plain depths (the shadow-map debug view), the cubes' faces too.
        let depth_sampler = sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, vk::Filter::NEAREST, None)?;
        self.samplers.push(depth_sampler);
        let i = &self.images;
        let faces = vk::DescriptorImageInfo::default().sampler(depth_sampler).image_view(omni.faces_view).image_layout(depth_read);
        let image = |name: &str| {
            Some(Resource::Image(match name {
                "shadow_map" => info(shadow_sampler, &i[SHADOW_IMAGE], depth_read),
                "sky" => info(sky_sampler, &i[SKY_IMAGE], read_only),
                "albedo_map" => info(material_sampler, &i[ALBEDO_IMAGE], read_only),
                "normal_map" => info(material_sampler, &i[NORMAL_IMAGE], read_only),
                "shadow_depth" => info(depth_sampler, &i[SHADOW_IMAGE], depth_read),
                "omni_shadows" => info(omni_sampler, &omni.cubes, depth_read),
                "omni_faces" => faces,
                _ => return None,
            }))
        };
        let resource = |name: &str| match name {
            "ShadowAtlasBuffer" => Some(Resource::Buffer(omni.atlas.depths.raw)),
            "ShadowAtlasTileBuffer" => Some(Resource::Buffer(omni.atlas.tiles.raw)),
            _ => image(name).or_else(|| environment.resource(name)),
        };
        self.set_layout.write(ctx, self.set, &resource)?;
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for image in &mut self.images {
            image.destroy(ctx);
        }
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            for s in self.samplers.drain(..) {
                ctx.device.destroy_sampler(s, None);
            }
            ctx.device.destroy_descriptor_pool(self.pool, None);
        }
        self.pool = vk::DescriptorPool::null();
        self.set_layout.destroy(ctx);
    }
}

impl ml_vk::Release for SceneTextures {
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
