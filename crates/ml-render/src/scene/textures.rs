//! Set 1 of every shading pipeline: the scene's textures. For the blinn-phong model a sky
//! cubemap for reflections, the albedo and normal maps (all made by our code:
//! ml_cpu::textures); the seed model binds 1×1 stand-ins it never samples. What other parts
//! of the scene bind there joins the set by name: the environment light's maps
//! (crate::environment), the shadow stores' maps and atlas (crate::shadows). The layout is
//! textures.glsl's and environment.glsl's set 1, as reflected from the shaders.

use crate::descriptors::{self, Resource, SetLayout};
use ml_cpu::textures;
use ml_vk::descriptors::allocate_set;
use ml_vk::image::{sampler, texture_with, ImageShape};
use ml_vk::{vk, Context, Image, VkError};

const MATERIAL_MAP_SIZE: u32 = 256;
const SKY_SIZE: u32 = 64;

pub struct SceneTextures {
    pub set_layout: SetLayout,
    pub set: vk::DescriptorSet,
    pool: vk::DescriptorPool,
    images: Vec<Image>,
    samplers: Vec<vk::Sampler>,
}

/// Places in `SceneTextures::images` (the order `create` makes them in).
const ALBEDO_IMAGE: usize = 0;
const NORMAL_IMAGE: usize = 1;
const SKY_IMAGE: usize = 2;

impl SceneTextures {
    /// The textures: with `blinn_phong` the real maps, else 1×1 stand-ins; the set binds them
    /// and what `others` names (a binding no one names is an error).
    pub fn new(ctx: &Context, blinn_phong: bool, others: &dyn Fn(&str) -> Option<Resource>) -> Result<SceneTextures, VkError> {
        let t = SceneTextures {
            set_layout: SetLayout::null(),
            set: vk::DescriptorSet::null(),
            pool: vk::DescriptorPool::null(),
            images: Vec::new(),
            samplers: Vec::new(),
        };
        ml_vk::build(ctx, t, |t| t.create(ctx, blinn_phong, others))
    }

    fn create(&mut self, ctx: &Context, real: bool, others: &dyn Fn(&str) -> Option<Resource>) -> Result<(), VkError> {
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
        let material_sampler = sampler(ctx, vk::SamplerAddressMode::REPEAT, vk::Filter::LINEAR, None)?;
        self.samplers.push(material_sampler);
        let sky_sampler = sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, vk::Filter::LINEAR, None)?;
        self.samplers.push(sky_sampler);
        let info = |sampler: vk::Sampler, image: &Image, layout: vk::ImageLayout| {
            vk::DescriptorImageInfo::default().sampler(sampler).image_view(image.view).image_layout(layout)
        };
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let i = &self.images;
        let resource = |name: &str| {
            Some(Resource::Image(match name {
                "sky" => info(sky_sampler, &i[SKY_IMAGE], read_only),
                "albedo_map" => info(material_sampler, &i[ALBEDO_IMAGE], read_only),
                "normal_map" => info(material_sampler, &i[NORMAL_IMAGE], read_only),
                _ => return others(name),
            }))
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
