//! Set 2 of the mesh pipelines: an object's own textures (glTF base colour, sRGB, and normal
//! map), mipmapped, bound per draw. One descriptor set per distinct pair an object uses, and
//! one of white stand-ins for objects with none (ObjectData.textures tells the shaders what
//! to sample). A set per draw rather than one array indexed per draw: lavapipe cannot index
//! sampler arrays dynamically.

use crate::scene_textures::sampler;
use ml_cpu::scene::{Object, ObjectTextures};
use ml_cpu::textures::TextureImage;
use ml_vk::descriptors::{allocate_set, write_image};
use ml_vk::image::texture_with;
use ml_vk::{shader, vk, Context, Image, ImageShape, VkError, VkResultExt};
use std::collections::HashMap;

const BINDING_BASE_COLOR: u32 = 0;
const BINDING_NORMAL: u32 = 1;

pub struct ObjectTextureSets {
    pub set_layout: vk::DescriptorSetLayout,
    /// Per object of the scene, the set its draws bind.
    pub per_object: Vec<vk::DescriptorSet>,
    pool: vk::DescriptorPool,
    images: Vec<Image>,
    sampler: vk::Sampler,
}

impl ObjectTextureSets {
    /// Upload `textures` and make the sets `objects` need.
    pub fn new(ctx: &Context, textures: &[TextureImage], objects: &[Object]) -> Result<ObjectTextureSets, VkError> {
        let sets = ObjectTextureSets {
            set_layout: vk::DescriptorSetLayout::null(),
            per_object: Vec::new(),
            pool: vk::DescriptorPool::null(),
            images: Vec::new(),
            sampler: vk::Sampler::null(),
        };
        ml_vk::build(ctx, sets, |s| s.create(ctx, textures, objects))
    }

    fn create(&mut self, ctx: &Context, textures: &[TextureImage], objects: &[Object]) -> Result<(), VkError> {
        let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        self.set_layout =
            shader::set_layout(ctx, &[(BINDING_BASE_COLOR, sampled), (BINDING_NORMAL, sampled)], vk::ShaderStageFlags::FRAGMENT)?;
        for (i, t) in textures.iter().enumerate() {
            let mips = t.mips();
            let levels: Vec<Vec<&[u8]>> = mips.iter().map(|l| vec![l.as_slice()]).collect();
            let extent = vk::Extent2D { width: t.width, height: t.height };
            let shape = ImageShape { extent, levels: mips.len() as u32, layers: 1, view: vk::ImageViewType::TYPE_2D };
            let format = if t.srgb { vk::Format::R8G8B8A8_SRGB } else { vk::Format::R8G8B8A8_UNORM };
            self.images.push(texture_with(ctx, &format!("object texture {i}"), shape, format, &levels)?);
        }
        let white = [255u8; 4];
        let one = ImageShape { extent: vk::Extent2D { width: 1, height: 1 }, levels: 1, layers: 1, view: vk::ImageViewType::TYPE_2D };
        self.images.push(texture_with(ctx, "no object texture", one, vk::Format::R8G8B8A8_UNORM, &[vec![&white[..]]])?);
        let stand_in = self.images.len() - 1;
        // Repeating, trilinear (glTF's samplers are not read yet).
        self.sampler = sampler(ctx, vk::SamplerAddressMode::REPEAT, vk::Filter::LINEAR, None)?;
        let mut pairs: Vec<ObjectTextures> = Vec::new();
        for o in objects {
            if !pairs.contains(&o.textures) {
                pairs.push(o.textures);
            }
        }
        let n = pairs.len().max(1) as u32;
        let sizes = [vk::DescriptorPoolSize { ty: sampled, descriptor_count: 2 * n }];
        // SAFETY: valid device and create info.
        self.pool =
            unsafe { ctx.device.create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(n).pool_sizes(&sizes), None) }
                .ctx("vkCreateDescriptorPool")?;
        let mut by_pair = HashMap::new();
        for pair in pairs {
            let set = allocate_set(ctx, self.pool, self.set_layout)?;
            for (binding, texture) in [(BINDING_BASE_COLOR, pair.base_color), (BINDING_NORMAL, pair.normal)] {
                let image = &self.images[texture.map_or(stand_in, |i| i as usize)];
                let info = vk::DescriptorImageInfo::default()
                    .sampler(self.sampler)
                    .image_view(image.view)
                    .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
                write_image(ctx, set, binding, sampled, info);
            }
            by_pair.insert(pair, set);
        }
        self.per_object = objects.iter().map(|o| by_pair[&o.textures]).collect();
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for image in &mut self.images {
            image.destroy(ctx);
        }
        // SAFETY: the device is idle (the caller's contract); null handles are ignored.
        unsafe {
            ctx.device.destroy_sampler(self.sampler, None);
            ctx.device.destroy_descriptor_pool(self.pool, None);
            ctx.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
        self.sampler = vk::Sampler::null();
        self.pool = vk::DescriptorPool::null();
        self.set_layout = vk::DescriptorSetLayout::null();
    }
}

impl ml_vk::Release for ObjectTextureSets {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
