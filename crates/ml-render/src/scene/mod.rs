//! The scene on the GPU, shared by every pass and frame: meshes, the object and spot-cone
//! buffers, the scene's textures (set 1 of every shading pipeline: the sun's shadow map, the
//! sky, material maps, the point-light shadow cubes) and each object's own textures (set 2).

pub mod meshlets;
pub mod object_data;
pub mod object_textures;
pub mod omni_shadow;
pub mod ray_geometry;
pub mod shadow_atlas;
pub mod shadow_raster;
pub mod shadow_settings;
pub mod sun_shadow;
pub mod textures;

use crate::environment::EnvironmentMaps;
use crate::error::RenderError;
use crate::gpu_mesh::SceneMeshes;
use crate::scene::meshlets::{storage_buffer_with, MeshletGeometry, MeshletGeometryView};
use crate::scene::object_data::{object_data, SurfaceVariant};
use crate::scene::object_textures::ObjectTextureSets;
use crate::scene::omni_shadow::OmniShadows;
use crate::scene::ray_geometry::RayGeometry;
use crate::scene::shadow_settings::{OmniShadowSettings, SunShadowMode};
use crate::scene::textures::SceneTextures;
use crate::targets::{depth_format, Output};
use ml_cpu::alpha_mask::AlphaMasks;
use ml_cpu::blinn_phong::shadow_view_proj;
use ml_cpu::gpu_types::{DirectionalLightData, LightCone, ObjectData};
use ml_cpu::scene::Scene;
use ml_vk::{release_on_error, vk, Buffer, Context};

pub struct SceneGpu {
    pub meshes: SceneMeshes,
    /// Every object's transform and material (draws push their index; the G-buffer stores it).
    pub objects: Buffer,
    /// Spot cones, parallel to the lights (static: only positions animate).
    pub cones: Buffer,
    /// The directional lights (static).
    pub directional: Buffer,
    /// The alpha of every texture a masked object cuts with (ml_cpu::alpha_mask).
    pub alpha_masks: Buffer,
    /// The surface variants (masked, double-sided) the objects need: the mesh passes make a
    /// pipeline for each.
    pub surface_variants: Vec<SurfaceVariant>,
    pub textures: SceneTextures,
    /// The environment light, prefiltered (stand-ins without one): part of the texture set.
    pub environment: EnvironmentMaps,
    pub object_textures: ObjectTextureSets,
    /// Point-light shadow cubes (a stand-in without shadowed lights): part of the scene's
    /// texture set, rendered each frame by the omni-shadow pass.
    pub omni: OmniShadows,
    /// The sun's shadow-map view-projection (blinn-phong).
    pub shadow_view_proj: glam::Mat4,
    /// How long the sun's shadow rays are: from any point of the scene's box beyond it.
    pub sun_ray_length: f32,
    /// Whether the sun's shadow map is drawn (blinn-phong), and by whom.
    sun: Option<SunShadowMode>,
    /// GPU milliseconds the sun's shadow map took to draw (None: not drawn, or no timestamps).
    pub sun_shadow_ms: Option<f64>,
    /// The scene's meshlets, built once for every pass that draws them (the visibility
    /// technique, the compute shadow rasters of the point lights and the sun); None where
    /// the settings have no such pass.
    meshlets: Option<MeshletGeometry>,
    wants_meshlets: bool,
    /// The shadow rays' hierarchy of the objects (stand-ins where no light casts rays).
    pub rays: RayGeometry,
    wants_rays: bool,
}

impl SceneGpu {
    pub fn new(ctx: &Context, scene: &Scene, config: SceneConfig) -> Result<SceneGpu, RenderError> {
        let sun = config.sun;
        // Each of these needs the ones before it; a failure releases those.
        let gbuffer_depth = depth_format(ctx, Output::GBuffer)?;
        let has_masked = scene.objects.iter().any(|o| o.extras.masked());
        let mut omni = OmniShadows::new(ctx, config.omni, has_masked)?;
        let mut environment = release_on_error(ctx, EnvironmentMaps::new(ctx, scene.environment.as_ref()), &mut [&mut omni])?;
        let made = SceneTextures::new(ctx, sun.is_some(), gbuffer_depth, (&omni, &environment));
        let mut textures = release_on_error(ctx, made.map_err(RenderError::from), &mut [&mut omni, &mut environment])?;
        let made = ObjectTextureSets::new(ctx, &scene.textures, &scene.objects);
        let object_textures = release_on_error(ctx, made, &mut [&mut omni, &mut environment, &mut textures])?;
        let mut gpu = SceneGpu {
            meshes: SceneMeshes::empty(),
            objects: Buffer::null(),
            cones: Buffer::null(),
            directional: Buffer::null(),
            alpha_masks: Buffer::null(),
            surface_variants: SurfaceVariant::needed(&scene.objects),
            textures,
            environment,
            object_textures,
            omni,
            shadow_view_proj: glam::Mat4::IDENTITY,
            sun_ray_length: 1.0,
            sun,
            sun_shadow_ms: None,
            meshlets: None,
            wants_meshlets: config.meshlets,
            rays: RayGeometry::null(),
            // Directional lights cast their shadows by rays in every point-light shadow mode.
            wants_rays: config.omni.is_some_and(|o| o.rays() || !scene.directional.is_empty()) || config.sun == Some(SunShadowMode::Rays),
        };
        // One cone per light where the scene has spots; else one the shaders never read.
        let cones = if scene.cones.is_empty() { vec![LightCone::NONE] } else { scene.cones.clone() };
        // Every directional light (frame.directional_count says how many); one stand-in if none.
        let mut directional: Vec<DirectionalLightData> = scene
            .directional
            .iter()
            .map(|d| DirectionalLightData { direction: d.direction.extend(0.0).to_array(), color: d.color.extend(0.0).to_array() })
            .collect();
        if directional.is_empty() {
            directional.push(DirectionalLightData::default());
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let made = Buffer::device_local_with(ctx, "light cones", bytemuck::cast_slice(&cones), storage)
            .and_then(|cones| {
                gpu.cones = cones;
                Buffer::device_local_with(ctx, "directional lights", bytemuck::cast_slice(&directional), storage)
            })
            .map_err(RenderError::from)
            .and_then(|directional| {
                gpu.directional = directional;
                gpu.upload_objects(ctx, scene)
            });
        if let Err(e) = made {
            gpu.destroy(ctx);
            return Err(e);
        }
        Ok(gpu)
    }

    /// The scene's objects on the GPU: its meshes, the object buffer, and (blinn-phong) the
    /// sun's shadow map of them.
    fn upload_objects(&mut self, ctx: &Context, scene: &Scene) -> Result<(), RenderError> {
        self.meshes = SceneMeshes::upload(ctx, scene)?;
        let masks = AlphaMasks::pack(scene).map_err(|e| RenderError::Invalid(e.to_string()))?;
        self.alpha_masks = storage_buffer_with(ctx, "alpha masks", bytemuck::cast_slice(&masks.words))?;
        let objects: Vec<ObjectData> = scene.objects.iter().map(|o| object_data(o, &masks, &scene.textures)).collect();
        self.objects = Buffer::device_local_with(ctx, "objects", bytemuck::cast_slice(&objects), vk::BufferUsageFlags::STORAGE_BUFFER)?;
        self.omni.bind_casters(ctx, (self.objects.raw, self.alpha_masks.raw))?;
        if self.wants_meshlets {
            self.meshlets = Some(MeshletGeometry::build(ctx, scene, &self.object_textures.set_index)?);
        }
        self.rays = RayGeometry::new(ctx, scene, self.wants_rays)?;
        let (lo, hi) = scene.bounds();
        self.shadow_view_proj = shadow_view_proj(lo, hi, scene.blinn_phong.sun_direction);
        self.sun_ray_length = (hi - lo).length() + 1.0;
        if let Some(mode) = self.sun {
            let view_proj = self.shadow_view_proj;
            let inputs = sun_shadow::ShadowInputs {
                scene,
                meshes: &self.meshes,
                objects: self.objects.raw,
                alpha_masks: self.alpha_masks.raw,
                view_proj,
                mode,
                meshlets: self.meshlets.as_ref().map(MeshletGeometry::view),
            };
            self.sun_shadow_ms = self.textures.render_shadow_map(ctx, &inputs)?;
        }
        Ok(())
    }

    /// Draw `scene`'s objects from now on (no frame in flight): new meshes, object buffer and
    /// sun shadow map. Only for scenes without object textures (every object binds the one
    /// set of stand-ins).
    pub fn replace_objects(&mut self, ctx: &Context, scene: &Scene) -> Result<(), RenderError> {
        // The passes were made for the surface variants (and the masked shadow pipeline) of the
        // objects before.
        if let Some(v) = SurfaceVariant::needed(&scene.objects).into_iter().find(|v| !self.surface_variants.contains(v)) {
            return Err(RenderError::Internal(format!("replaced objects need a surface the renderer was not made for ({v:?})")));
        }
        self.release_objects(ctx);
        let stand_ins = self.object_textures.sets[0];
        self.object_textures.per_object = vec![stand_ins; scene.objects.len()];
        self.object_textures.set_index = vec![0; scene.objects.len()];
        self.upload_objects(ctx, scene)
    }

    fn release_objects(&mut self, ctx: &Context) {
        self.meshes.destroy(ctx);
        self.objects.destroy(ctx);
        self.alpha_masks.destroy(ctx);
        if let Some(mut meshlets) = self.meshlets.take() {
            meshlets.destroy(ctx);
        }
        self.rays.destroy(ctx);
    }

    /// The scene's buffers that shaders bind, under their blocks' names (a frame's table of
    /// resources holds them).
    pub fn named_buffers(&self) -> Vec<(&'static str, vk::Buffer)> {
        let mut named = vec![
            ("ObjectBuffer", self.objects.raw),
            ("LightConeBuffer", self.cones.raw),
            ("DirectionalLightBuffer", self.directional.raw),
            ("AlphaMaskBuffer", self.alpha_masks.raw),
        ];
        named.extend(self.rays.named_buffers());
        named
    }

    /// The scene's images that passes declare (`sync`), under their names: the shadow cubes.
    pub fn named_image(&self, name: &str) -> Option<(vk::Image, vk::ImageAspectFlags)> {
        (name == crate::sync::SHADOW_CUBES).then_some((self.omni.cubes.raw, vk::ImageAspectFlags::DEPTH))
    }

    /// The scene's meshlets, for a pass that draws them.
    pub fn meshlets(&self) -> Result<MeshletGeometryView, RenderError> {
        self.meshlets
            .as_ref()
            .map(MeshletGeometry::view)
            .ok_or_else(|| RenderError::Internal("the scene's meshlets were not built for these settings".into()))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.release_objects(ctx);
        self.cones.destroy(ctx);
        self.directional.destroy(ctx);
        self.textures.destroy(ctx);
        self.environment.destroy(ctx);
        self.object_textures.destroy(ctx);
        self.omni.destroy(ctx);
    }
}

/// What the scene's GPU resources are made for (the render settings' `scene_config`): which
/// shadow stores, and whether some pass draws the scene's meshlets.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneConfig {
    /// Whether the sun's shadow map is drawn (blinn-phong), and by whom.
    pub sun: Option<SunShadowMode>,
    /// Point-light shadows (None: the stand-in).
    pub omni: Option<OmniShadowSettings>,
    /// Whether a pass draws the scene's meshlets.
    pub meshlets: bool,
}
