//! Set 2 of the mesh pipelines: an object's own textures (glTF's base colour, normal,
//! metallic-roughness, occlusion and emissive), mipmapped, each with its glTF sampler, bound
//! per draw. One descriptor set per distinct combination objects use, white stand-ins in the
//! slots an object leaves empty (ObjectPush.ids.y tells the shaders which to sample). A set
//! per draw rather than one array indexed per draw: lavapipe cannot index sampler arrays
//! dynamically.

use ml_cpu::scene::{Object, ObjectTextures, TEXTURE_SLOTS};
use ml_cpu::textures::{Filter, TextureImage, TextureSampler, Wrap};
use ml_vk::descriptors::{allocate_set, write_image};
use ml_vk::image::texture_with;
use ml_vk::{shader, vk, Context, Image, ImageShape, VkError, VkResultExt};
use std::collections::HashMap;

pub struct ObjectTextureSets {
    pub set_layout: vk::DescriptorSetLayout,
    /// Per object of the scene, the set its draws bind.
    pub per_object: Vec<vk::DescriptorSet>,
    /// The distinct sets (texture sets), and per object the index of its own among them
    /// (the visibility lighting shades one texture set per dispatch).
    pub sets: Vec<vk::DescriptorSet>,
    pub set_index: Vec<u32>,
    pool: vk::DescriptorPool,
    images: Vec<Image>,
    samplers: Vec<vk::Sampler>,
}

impl ObjectTextureSets {
    /// Upload `textures` and make the sets `objects` need.
    pub fn new(ctx: &Context, textures: &[TextureImage], objects: &[Object]) -> Result<ObjectTextureSets, VkError> {
        let sets = ObjectTextureSets {
            set_layout: vk::DescriptorSetLayout::null(),
            per_object: Vec::new(),
            sets: Vec::new(),
            set_index: Vec::new(),
            pool: vk::DescriptorPool::null(),
            images: Vec::new(),
            samplers: Vec::new(),
        };
        ml_vk::build(ctx, sets, |s| s.create(ctx, textures, objects))
    }

    fn create(&mut self, ctx: &Context, textures: &[TextureImage], objects: &[Object]) -> Result<(), VkError> {
        let sampled = vk::DescriptorType::COMBINED_IMAGE_SAMPLER;
        // Binding i: slot i of ObjectTextures::slots.
        let bindings: Vec<(u32, vk::DescriptorType)> = (0..TEXTURE_SLOTS as u32).map(|b| (b, sampled)).collect();
        // Fragment shaders (per draw) and the visibility lighting (per texture set) read them.
        self.set_layout = shader::set_layout(ctx, &bindings, vk::ShaderStageFlags::FRAGMENT | vk::ShaderStageFlags::COMPUTE)?;
        // One image per distinct texels and colour space: textures that share an image's
        // texels (one glTF image under several samplers) share its upload and mip chain.
        let mut by_texels: HashMap<(*const u8, bool), usize> = HashMap::new();
        let mut image_of = Vec::with_capacity(textures.len());
        for (i, t) in textures.iter().enumerate() {
            let key = (t.rgba.as_ptr(), t.srgb);
            if let Some(&image) = by_texels.get(&key) {
                image_of.push(image);
                continue;
            }
            let mips = t.mips();
            let levels: Vec<Vec<&[u8]>> = mips.iter().map(|l| vec![l.as_slice()]).collect();
            let extent = vk::Extent2D { width: t.width, height: t.height };
            let shape = ImageShape { extent, levels: mips.len() as u32, layers: 1, view: vk::ImageViewType::TYPE_2D };
            let format = if t.srgb { vk::Format::R8G8B8A8_SRGB } else { vk::Format::R8G8B8A8_UNORM };
            by_texels.insert(key, self.images.len());
            image_of.push(self.images.len());
            self.images.push(texture_with(ctx, &format!("object texture {i}"), shape, format, &levels)?);
        }
        let white = [255u8; 4];
        let one = ImageShape { extent: vk::Extent2D { width: 1, height: 1 }, levels: 1, layers: 1, view: vk::ImageViewType::TYPE_2D };
        self.images.push(texture_with(ctx, "no object texture", one, vk::Format::R8G8B8A8_UNORM, &[vec![&white[..]]])?);
        let stand_in = self.images.len() - 1;
        // One sampler per distinct glTF sampler (the stand-in uses the default's).
        let mut by_sampler: HashMap<TextureSampler, vk::Sampler> = HashMap::new();
        for desc in textures.iter().map(|t| t.sampler).chain([TextureSampler::default()]) {
            if let std::collections::hash_map::Entry::Vacant(slot) = by_sampler.entry(desc) {
                let made = create_sampler(ctx, &desc)?;
                self.samplers.push(made);
                slot.insert(made);
            }
        }
        let mut combinations: Vec<ObjectTextures> = Vec::new();
        for o in objects {
            if !combinations.contains(&o.textures) {
                combinations.push(o.textures);
            }
        }
        // A scene without objects still binds a set (of stand-ins).
        if combinations.is_empty() {
            combinations.push(ObjectTextures::default());
        }
        let n = combinations.len() as u32;
        let sizes = [vk::DescriptorPoolSize { ty: sampled, descriptor_count: TEXTURE_SLOTS as u32 * n }];
        // SAFETY: valid device and create info.
        self.pool =
            unsafe { ctx.device.create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(n).pool_sizes(&sizes), None) }
                .ctx("vkCreateDescriptorPool")?;
        let mut by_combination = HashMap::new();
        for combination in combinations {
            let set = allocate_set(ctx, self.pool, self.set_layout)?;
            for (binding, texture) in (0u32..).zip(combination.slots()) {
                let (image, desc) = match texture {
                    Some(i) => (image_of[i as usize], textures[i as usize].sampler),
                    None => (stand_in, TextureSampler::default()),
                };
                let info = vk::DescriptorImageInfo::default()
                    .sampler(by_sampler[&desc])
                    .image_view(self.images[image].view)
                    .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
                write_image(ctx, set, binding, sampled, info);
            }
            by_combination.insert(combination, self.sets.len() as u32);
            self.sets.push(set);
        }
        self.set_index = objects.iter().map(|o| by_combination[&o.textures]).collect();
        self.per_object = self.set_index.iter().map(|&i| self.sets[i as usize]).collect();
        Ok(())
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for image in &mut self.images {
            image.destroy(ctx);
        }
        // SAFETY: the device is idle (the caller's contract); null handles are ignored.
        unsafe {
            for sampler in self.samplers.drain(..) {
                ctx.device.destroy_sampler(sampler, None);
            }
            ctx.device.destroy_descriptor_pool(self.pool, None);
        }
        self.pool = vk::DescriptorPool::null();
        self.set_layout = vk::DescriptorSetLayout::null();
    }
}

/// The Vulkan sampler of a glTF sampler. Without mipmaps only the base level is sampled
/// (max LOD 0, as glTF's NEAREST and LINEAR minification filters mean).
fn create_sampler(ctx: &Context, desc: &TextureSampler) -> Result<vk::Sampler, VkError> {
    let filter = |f: Filter| match f {
        Filter::Nearest => vk::Filter::NEAREST,
        Filter::Linear => vk::Filter::LINEAR,
    };
    let wrap = |w: Wrap| match w {
        Wrap::Repeat => vk::SamplerAddressMode::REPEAT,
        Wrap::MirroredRepeat => vk::SamplerAddressMode::MIRRORED_REPEAT,
        Wrap::ClampToEdge => vk::SamplerAddressMode::CLAMP_TO_EDGE,
    };
    let mipmap_mode = match desc.mipmap {
        Some(Filter::Linear) => vk::SamplerMipmapMode::LINEAR,
        Some(Filter::Nearest) | None => vk::SamplerMipmapMode::NEAREST,
    };
    let info = vk::SamplerCreateInfo::default()
        .mag_filter(filter(desc.mag))
        .min_filter(filter(desc.min))
        .mipmap_mode(mipmap_mode)
        .address_mode_u(wrap(desc.wrap_u))
        .address_mode_v(wrap(desc.wrap_v))
        .address_mode_w(vk::SamplerAddressMode::REPEAT)
        .max_lod(if desc.mipmap.is_some() { vk::LOD_CLAMP_NONE } else { 0.0 });
    // SAFETY: valid device and create info.
    unsafe { ctx.device.create_sampler(&info, None) }.ctx("vkCreateSampler")
}

impl ml_vk::Release for ObjectTextureSets {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
