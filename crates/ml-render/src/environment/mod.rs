//! Environment light on the GPU: the scene's environment (`ml_cpu::environment`) prefiltered
//! once, when the scene is loaded, into what every shading path reads at set 1
//! (environment/environment.glsl): a cube of radiance prefiltered by GGX lobes of growing
//! roughness down its mip levels, the BRDF's split-sum table and the nine diffuse
//! coefficients. All of it is made by compute shaders in one submission: the equirectangular
//! image resampled into a cube, that cube's mip chain, the coefficients projected from a small
//! level of it, the table, then the specular levels read from the chain
//! (docs/DESIGN.md#environment-light). A scene without an environment binds stand-ins its
//! shaders never read (their ENVIRONMENT constant is off).

use crate::background::Background;
use crate::descriptors::{self, Resource, SetLayout};
use crate::error::{RenderError, SettingsError};
use crate::feature::Feature;
use crate::report::{FeatureStats, FrameStats};
use crate::scene_part::{FrameCounts, OwnedPart, PartHost, ScenePart};
use crate::settings::RenderSettings;
use crate::specialization::Constants;
use ml_cpu::environment::Environment;
use ml_cpu::gpu_types::EnvironmentData;
use ml_cpu::scene::Scene;
use ml_cpu::shading_model::ShadingModel;
use ml_shaders::Shader;
use ml_vk::image::{image_transition, sampler, texture_with, ImageShape};
use ml_vk::{shader, vk, Buffer, Context, GpuTimer, Image, VkError, VkResultExt};

/// The environment light as the assembly lists it (`feature`): its maps, made with each scene;
/// its constant, `ENVIRONMENT` (environment/environment.glsl); the background it may show.
pub const FEATURE: Feature = Feature { part: Some(make_part), lighting, check_scene, ..Feature::NONE };

/// Whether the scene's environment lights it: the pbr model and a scene with one (else the
/// constant ambient).
fn lights_scene(model: ShadingModel, scene: &Scene) -> bool {
    model == ShadingModel::Pbr && scene.sections.get::<Environment>().is_some()
}

/// Reject the environment as the background where it does not light the scene (the model
/// lights with none, or the model is not pbr).
fn check_scene(settings: &RenderSettings, scene: &Scene) -> Result<(), SettingsError> {
    if settings.background == Background::Environment && !lights_scene(settings.shading, scene) {
        return Err(SettingsError::SceneRefused(
            "--background environment needs an environment: the pbr model (--shading pbr) with --environment FILE or sky, or a scene file's own",
        ));
    }
    Ok(())
}

fn lighting(settings: &RenderSettings, scene: &Scene) -> Constants {
    Constants::of(&[&[("ENVIRONMENT", u32::from(lights_scene(settings.shading, scene)))]])
}

/// Mip levels of the specular cube: roughness level / (levels − 1), 0 (a mirror) to 1.
pub const SPECULAR_LEVELS: u32 = 6;
/// Texels per side of the specular cube's level 0. Each level must resolve its lobe (GGX's
/// width about α = roughness² rad wants about 2π/α texels a face): 256 down to 8 at roughness 1
/// does, whatever the image's own size (32 down to 1 was 29/255 off the reference at roughness
/// 1; 128 down to 4, 8/255; 128 down to 8 in five levels, 13/255 at roughness 0.2, between a
/// mirror and 0.25).
pub const SPECULAR_SIZE: u32 = 256;
/// Texels per side of the BRDF table (n·v along x, roughness along y).
pub const BRDF_TABLE_SIZE: u32 = 128;
/// GGX samples a texel of specular level `level` takes: more where the lobe is wider and the
/// level smaller (each level then costs about the same). Filtered importance sampling reads
/// each sample from the mip its share of the lobe covers, which blurs more the fewer the
/// samples: 128 at every level left roughness 1 at 10/255 from the reference, 1,024 at 3/255.
pub fn prefilter_samples(level: u32) -> u32 {
    (128u32 << (2 * level.saturating_sub(1))).min(2048)
}
/// Texels per side of the cube level the diffuse coefficients are projected from (at most).
const SH_LEVEL_SIZE: u32 = 32;
const FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;

/// The environment's prefiltered light, or stand-ins for a scene without one.
pub struct EnvironmentMaps {
    /// The image as a cube with its box mip chain (the background); the specular cube where
    /// there is no environment.
    radiance: Image,
    specular: Image,
    brdf: Image,
    /// EnvironmentData: the coefficients (written by the prefilter), rotation and intensity.
    pub buffer: Buffer,
    sampler: vk::Sampler,
    /// What the prefiltering made and took (None: no environment).
    pub stats: Option<EnvironmentStats>,
}

/// The environment's row of the timing table.
#[derive(Clone, Copy, Debug)]
pub struct EnvironmentStats {
    /// The image's size and its cube's face.
    pub image: (u32, u32),
    pub face_size: u32,
    /// GPU milliseconds of the prefiltering (None: no timestamps).
    pub prefilter_ms: Option<f64>,
}

impl FeatureStats for EnvironmentStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let ms = self.prefilter_ms.map_or_else(|| "not timed".into(), |ms| format!("{ms:.3} ms"));
        let (w, h) = self.image;
        vec![(
            "environment",
            format!(
                "{w}x{h} image, prefiltered once at load in {ms} (a {f}² cube; a {SPECULAR_SIZE}² specular cube of {SPECULAR_LEVELS} roughness levels; a {BRDF_TABLE_SIZE}² BRDF table; 9 diffuse coefficients)",
                f = self.face_size
            ),
        )]
    }
}

/// The face size of the cube an equirectangular image of `width` texels becomes: about as
/// sharp (a quarter of its width), a power of two from 16 to 1024.
pub fn face_size(width: u32) -> u32 {
    (width / 4).next_power_of_two().clamp(16, 1024)
}

impl EnvironmentMaps {
    /// `environment` prefiltered, or (None) the stand-ins.
    pub fn new(ctx: &Context, environment: Option<&Environment>) -> Result<EnvironmentMaps, RenderError> {
        let maps = EnvironmentMaps {
            radiance: Image::null(),
            specular: Image::null(),
            brdf: Image::null(),
            buffer: Buffer::null(),
            sampler: vk::Sampler::null(),
            stats: None,
        };
        ml_vk::build(ctx, maps, |m| {
            m.sampler = sampler(ctx, vk::SamplerAddressMode::CLAMP_TO_EDGE, vk::Filter::LINEAR, None)?;
            match environment {
                None => m.stand_ins(ctx),
                Some(env) => m.prefilter(ctx, env),
            }
        })
    }

    fn stand_ins(&mut self, ctx: &Context) -> Result<(), RenderError> {
        let flat = ImageShape { extent: vk::Extent2D { width: 1, height: 1 }, levels: 1, layers: 1, view: vk::ImageViewType::TYPE_2D };
        let cube = ImageShape { layers: 6, view: vk::ImageViewType::CUBE, ..flat };
        let black = [0u8; 4];
        let rgba = vk::Format::R8G8B8A8_UNORM;
        self.specular = texture_with(ctx, "environment stand-in", cube, rgba, &[vec![&black[..]; 6]])?;
        self.brdf = texture_with(ctx, "environment table stand-in", flat, rgba, &[vec![&black[..]]])?;
        self.buffer = data_buffer(ctx, &EnvironmentData::default())?;
        Ok(())
    }

    fn prefilter(&mut self, ctx: &Context, env: &Environment) -> Result<(), RenderError> {
        let image = &env.image;
        let most = ctx.info.limits.max_image_dimension2_d;
        if image.width > most {
            let (w, h) = (image.width, image.height);
            return Err(RenderError::Invalid(format!("the environment image is {w}x{h}: this device takes images at most {most} wide")));
        }
        let size = face_size(image.width);
        let source_levels = size.ilog2() + 1;
        let usage = vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::SAMPLED;
        let cube = |side, levels| ImageShape {
            extent: vk::Extent2D { width: side, height: side },
            levels,
            layers: 6,
            view: vk::ImageViewType::CUBE,
        };
        let specular = cube(SPECULAR_SIZE, SPECULAR_LEVELS);
        self.specular = Image::new(ctx, "environment specular", specular, FORMAT, usage, vk::ImageAspectFlags::COLOR)?;
        let table = vk::Extent2D { width: BRDF_TABLE_SIZE, height: BRDF_TABLE_SIZE };
        self.brdf = Image::new_2d(ctx, "environment brdf table", table, FORMAT, usage, vk::ImageAspectFlags::COLOR)?;
        self.buffer = data_buffer(ctx, &view_data(env))?;
        let texels: Vec<[f32; 4]> = image.texels.iter().map(|t| [t[0], t[1], t[2], 1.0]).collect();
        let flat = ImageShape {
            extent: vk::Extent2D { width: image.width, height: image.height },
            levels: 1,
            layers: 1,
            view: vk::ImageViewType::TYPE_2D,
        };
        let mut equirect =
            texture_with(ctx, "environment image", flat, vk::Format::R32G32B32A32_SFLOAT, &[vec![bytemuck::cast_slice(&texels)]])?;
        // Kept: the background shows it.
        self.radiance = match Image::new(ctx, "environment cube", cube(size, source_levels), FORMAT, usage, vk::ImageAspectFlags::COLOR) {
            Ok(s) => s,
            Err(e) => {
                equirect.destroy(ctx);
                return Err(e.into());
            }
        };
        let mut work = Prefilter::new();
        let done = work.record(ctx, (&equirect, &self.radiance), (&self.specular, &self.brdf, self.buffer.raw), self.sampler);
        work.destroy(ctx);
        equirect.destroy(ctx);
        self.stats = Some(EnvironmentStats { image: (image.width, image.height), face_size: size, prefilter_ms: done? });
        Ok(())
    }

    /// Turn and scale the environment as `env` says (its image unchanged), with no frame in
    /// flight: only the CPU's part of EnvironmentData is written, the coefficients stay.
    pub fn set_view(&self, ctx: &Context, env: &Environment) -> Result<(), VkError> {
        let data = view_data(env);
        let from = std::mem::offset_of!(EnvironmentData, to_image);
        let bytes = &bytemuck::bytes_of(&data)[from..];
        ml_vk::commands::one_shot(ctx, |cmd| {
            let compute = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::FRAGMENT_SHADER;
            // SAFETY: recording; the range lies within the buffer and is a multiple of 4 bytes.
            unsafe { ctx.device.cmd_update_buffer(cmd, self.buffer.raw, from as u64, bytes) };
            ml_vk::commands::memory_barrier(
                ctx,
                cmd,
                (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_WRITE),
                (compute, vk::AccessFlags::SHADER_READ),
            );
        })
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.radiance.destroy(ctx);
        self.specular.destroy(ctx);
        self.brdf.destroy(ctx);
        self.buffer.destroy(ctx);
        // SAFETY: no pending work uses it; a null handle is ignored.
        unsafe { ctx.device.destroy_sampler(self.sampler, None) };
        self.sampler = vk::Sampler::null();
    }
}

impl ScenePart for EnvironmentMaps {
    /// What set 1's environment bindings point at, by the names environment.glsl gives them.
    fn resource(&self, name: &str) -> Option<Resource> {
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let image = |i: &Image| {
            Resource::Image(vk::DescriptorImageInfo::default().sampler(self.sampler).image_view(i.view).image_layout(read_only))
        };
        match name {
            "environment_specular" => Some(image(&self.specular)),
            "environment_radiance" => Some(image(if self.radiance.raw == vk::Image::null() { &self.specular } else { &self.radiance })),
            "environment_brdf" => Some(image(&self.brdf)),
            "EnvironmentBuffer" => Some(Resource::Buffer(self.buffer.raw)),
            _ => None,
        }
    }

    /// The environment's row: its image and prefiltering (none for the stand-ins).
    fn report(&self, _counts: &FrameCounts, stats: &mut FrameStats) {
        if let Some(environment) = self.stats {
            stats.set_feature(environment);
        }
    }
}

impl OwnedPart for EnvironmentMaps {
    fn destroy(&mut self, ctx: &Context) {
        EnvironmentMaps::destroy(self, ctx);
    }
}

/// The scene's environment prefiltered (or the stand-ins), as a scene part.
fn make_part(ctx: &Context, scene: &Scene) -> Result<Box<dyn OwnedPart>, RenderError> {
    Ok(Box::new(EnvironmentMaps::new(ctx, scene.sections.get::<Environment>())?))
}

/// The environment's view on the renderer (`use ml_render::EnvironmentView`).
pub trait EnvironmentView {
    /// Light the scene with its environment at `intensity`, turned by `rotation` radians about
    /// +Y, from the next frame on (no new prefiltering: the turn and scale apply as it is
    /// read). False where the scene has no environment.
    fn set_environment_view(&mut self, intensity: f32, rotation: f32) -> Result<bool, RenderError>;
}

impl<H: PartHost> EnvironmentView for H {
    fn set_environment_view(&mut self, intensity: f32, rotation: f32) -> Result<bool, RenderError> {
        let access = self.part_access();
        let (Some(env), Some(maps)) = (access.scene.sections.get_mut::<Environment>(), access.parts.get_mut::<EnvironmentMaps>()) else {
            return Ok(false);
        };
        (env.intensity, env.rotation) = (intensity, rotation);
        access.ctx.wait_idle()?;
        maps.set_view(access.ctx, env)?;
        Ok(true)
    }
}

impl ml_vk::Release for EnvironmentMaps {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// EnvironmentData without its coefficients (the prefilter's part): `env`'s turn and intensity.
fn view_data(env: &Environment) -> EnvironmentData {
    let rotation = env.to_image();
    let column = |v: glam::Vec3| [v.x, v.y, v.z, 0.0];
    EnvironmentData {
        sh: [[0.0; 4]; 9],
        sheen_albedo: [[0.0; 16]; 16],
        to_image: [column(rotation.x_axis), column(rotation.y_axis), column(rotation.z_axis)],
        params: [env.intensity, (SPECULAR_LEVELS - 1) as f32, 0.0, 0.0],
    }
}

/// The buffer of `data` with the sheen's table (every scene's: material lobes need it with or
/// without an environment).
fn data_buffer(ctx: &Context, data: &EnvironmentData) -> Result<Buffer, VkError> {
    let mut data = *data;
    data.sheen_albedo = bytemuck::cast(ml_cpu::material_lobes::SHEEN_ALBEDO);
    Buffer::device_local_with(ctx, "environment", bytemuck::bytes_of(&data), vk::BufferUsageFlags::STORAGE_BUFFER)
}

/// The prefiltering's pipelines, sets and per-level views, made for one submission and
/// released after it.
struct Prefilter {
    layouts: Vec<SetLayout>,
    pipeline_layouts: Vec<vk::PipelineLayout>,
    pipelines: Vec<vk::Pipeline>,
    pool: vk::DescriptorPool,
    views: Vec<vk::ImageView>,
}

/// The prefilter's push constants (environment_prefilter.comp).
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct PrefilterPush {
    roughness: f32,
    samples: u32,
}

const SHADERS: [&Shader; 5] = [
    &ml_shaders::ENVIRONMENT_CUBE_COMP,
    &ml_shaders::ENVIRONMENT_DOWNSAMPLE_COMP,
    &ml_shaders::ENVIRONMENT_SH_COMP,
    &ml_shaders::ENVIRONMENT_BRDF_COMP,
    &ml_shaders::ENVIRONMENT_PREFILTER_COMP,
];
const CUBE: usize = 0;
const DOWNSAMPLE: usize = 1;
const SH: usize = 2;
const BRDF: usize = 3;
const SPECULAR: usize = 4;

impl Prefilter {
    fn new() -> Prefilter {
        Prefilter {
            layouts: Vec::new(),
            pipeline_layouts: Vec::new(),
            pipelines: Vec::new(),
            pool: vk::DescriptorPool::null(),
            views: Vec::new(),
        }
    }

    fn make_pipelines(&mut self, ctx: &Context, sets_per_shader: [u32; 5]) -> Result<Vec<Vec<vk::DescriptorSet>>, VkError> {
        for (i, s) in SHADERS.iter().enumerate() {
            self.layouts.push(SetLayout::new(ctx, &[(s, vk::ShaderStageFlags::COMPUTE)], 0)?);
            let push = [vk::PushConstantRange::default()
                .stage_flags(vk::ShaderStageFlags::COMPUTE)
                .size(std::mem::size_of::<PrefilterPush>() as u32)];
            let pushes: &[vk::PushConstantRange] = if i == SPECULAR { &push } else { &[] };
            self.pipeline_layouts.push(shader::pipeline_layout(ctx, &[self.layouts[i].raw], pushes)?);
            self.pipelines.push(crate::specialization::compute_pipeline(ctx, s, self.pipeline_layouts[i], &[])?);
        }
        let counted: Vec<(&SetLayout, u32)> = self.layouts.iter().zip(sets_per_shader).collect();
        self.pool = descriptors::pool(ctx, &counted)?;
        let mut sets = Vec::new();
        for (layout, n) in counted {
            sets.push((0..n).map(|_| ml_vk::descriptors::allocate_set(ctx, self.pool, layout.raw)).collect::<Result<Vec<_>, _>>()?);
        }
        Ok(sets)
    }

    /// A 2D-array view of mip `level` of cube `image` (its six faces), for storage.
    fn level_view(&mut self, ctx: &Context, image: &Image, level: u32) -> Result<vk::ImageView, VkError> {
        let range = vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .base_mip_level(level)
            .level_count(1)
            .layer_count(6);
        let info = vk::ImageViewCreateInfo::default()
            .image(image.raw)
            .view_type(vk::ImageViewType::TYPE_2D_ARRAY)
            .format(image.format)
            .subresource_range(range);
        // SAFETY: bound image; the level and layers lie within it.
        let view = unsafe { ctx.device.create_image_view(&info, None) }.ctx("vkCreateImageView")?;
        self.views.push(view);
        Ok(view)
    }

    /// Record and run the whole prefiltering: `source` (a cube with a full mip chain) from
    /// `equirect`, then the coefficients into `buffer`, the table and every level of
    /// `specular`, left for the shading paths to read. Its GPU milliseconds.
    fn record(
        &mut self,
        ctx: &Context,
        (equirect, source): (&Image, &Image),
        (specular, brdf, buffer): (&Image, &Image, vk::Buffer),
        linear: vk::Sampler,
    ) -> Result<Option<f64>, RenderError> {
        let size = source.extent.width;
        let source_levels = size.ilog2() + 1;
        let specular_levels = SPECULAR_LEVELS;
        let sh_level = size.ilog2().saturating_sub(SH_LEVEL_SIZE.ilog2());
        let sets = self.make_pipelines(ctx, [1, source_levels - 1, 1, 1, specular_levels])?;
        let general = vk::ImageLayout::GENERAL;
        let storage = |view| Resource::Image(vk::DescriptorImageInfo::default().image_view(view).image_layout(general));
        let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
        let sampled = |image: &Image| {
            Resource::Image(vk::DescriptorImageInfo::default().sampler(linear).image_view(image.view).image_layout(read_only))
        };
        let source_views: Vec<vk::ImageView> = (0..source_levels).map(|l| self.level_view(ctx, source, l)).collect::<Result<_, _>>()?;
        let specular_views: Vec<vk::ImageView> =
            (0..specular_levels).map(|l| self.level_view(ctx, specular, l)).collect::<Result<_, _>>()?;
        let brdf_view = brdf.view;
        let write =
            |shader: usize, set: vk::DescriptorSet, lookup: &dyn Fn(&str) -> Option<Resource>| self.layouts[shader].write(ctx, set, lookup);
        write(CUBE, sets[CUBE][0], &|n| match n {
            "equirect" => Some(sampled(equirect)),
            "cube_level" => Some(storage(source_views[0])),
            _ => None,
        })?;
        for level in 1..source_levels as usize {
            write(DOWNSAMPLE, sets[DOWNSAMPLE][level - 1], &|n| match n {
                "finer_level" => Some(storage(source_views[level - 1])),
                "coarser_level" => Some(storage(source_views[level])),
                _ => None,
            })?;
        }
        write(SH, sets[SH][0], &|n| match n {
            "sh_level" => Some(storage(source_views[sh_level as usize])),
            "EnvironmentBuffer" => Some(Resource::Buffer(buffer)),
            _ => None,
        })?;
        write(BRDF, sets[BRDF][0], &|n| (n == "brdf_table").then(|| storage(brdf_view)))?;
        for (level, view) in specular_views.iter().enumerate() {
            write(SPECULAR, sets[SPECULAR][level], &|n| match n {
                "source" => Some(sampled(source)),
                "specular_level" => Some(storage(*view)),
                _ => None,
            })?;
        }
        let mut timer = GpuTimer::new(ctx, 1)?;
        let d = &ctx.device;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let writes_done = (compute, vk::AccessFlags::SHADER_WRITE, general);
        let ran = ml_vk::commands::one_shot(ctx, |cmd| {
            timer.reset(ctx, cmd);
            timer.begin(ctx, cmd, 0);
            let undefined = (vk::PipelineStageFlags::TOP_OF_PIPE, vk::AccessFlags::empty(), vk::ImageLayout::UNDEFINED);
            for image in [source, specular, brdf] {
                image_transition(ctx, cmd, image.raw, undefined, writes_done);
            }
            let dispatch = |shader: usize, set: vk::DescriptorSet, groups: (u32, u32, u32)| {
                // SAFETY: recording; the pipeline, its layout and the set were made above.
                unsafe {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[shader]);
                    d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.pipeline_layouts[shader], 0, &[set], &[]);
                    d.cmd_dispatch(cmd, groups.0, groups.1, groups.2);
                }
            };
            let after_writes = || {
                let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
                ml_vk::commands::memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (compute, rw));
            };
            let groups = |side: u32, depth: u32| (side.div_ceil(8), side.div_ceil(8), depth);
            dispatch(CUBE, sets[CUBE][0], groups(size, 6));
            for level in 1..source_levels {
                after_writes();
                dispatch(DOWNSAMPLE, sets[DOWNSAMPLE][level as usize - 1], groups((size >> level).max(1), 6));
            }
            after_writes();
            dispatch(SH, sets[SH][0], (1, 1, 1));
            dispatch(BRDF, sets[BRDF][0], groups(BRDF_TABLE_SIZE, 1));
            let sampled_by_compute = (compute, vk::AccessFlags::SHADER_READ, read_only);
            image_transition(ctx, cmd, source.raw, writes_done, sampled_by_compute);
            for level in 0..specular_levels {
                let push =
                    PrefilterPush { roughness: level as f32 / (specular_levels - 1).max(1) as f32, samples: prefilter_samples(level) };
                // SAFETY: recording; the layout has this push-constant range.
                unsafe {
                    d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.pipelines[SPECULAR]);
                    d.cmd_push_constants(cmd, self.pipeline_layouts[SPECULAR], vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&push));
                }
                dispatch(SPECULAR, sets[SPECULAR][level as usize], groups(SPECULAR_SIZE >> level, 6));
            }
            // Everything written is read by the shading paths from here on.
            let readers = vk::PipelineStageFlags::FRAGMENT_SHADER | compute;
            for image in [specular, brdf] {
                image_transition(ctx, cmd, image.raw, writes_done, (readers, vk::AccessFlags::SHADER_READ, read_only));
            }
            ml_vk::commands::memory_barrier(ctx, cmd, (compute, vk::AccessFlags::SHADER_WRITE), (readers, vk::AccessFlags::SHADER_READ));
            timer.end(ctx, cmd, 0);
        });
        let ms = ran.map_err(RenderError::from).and_then(|()| Ok(timer.read_ms(ctx)?));
        timer.destroy(ctx);
        Ok(ms?.map(|passes| passes[0]))
    }

    fn destroy(&mut self, ctx: &Context) {
        for p in self.pipelines.drain(..) {
            ml_vk::shader::release_pipeline(ctx, p);
        }
        // Layouts are the context's.
        self.pipeline_layouts.clear();
        // SAFETY: the submission that used them has finished (or never ran); null handles are
        // ignored.
        unsafe {
            for v in self.views.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
            ctx.device.destroy_descriptor_pool(self.pool, None);
        }
        for mut l in self.layouts.drain(..) {
            l.destroy(ctx);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubes_are_about_as_sharp_as_their_images() {
        assert_eq!(face_size(512), 128);
        assert_eq!(face_size(2048), 512);
        assert_eq!(face_size(600), 256);
        assert_eq!(face_size(8), 16);
        assert_eq!(face_size(16384), 1024);
    }
}
