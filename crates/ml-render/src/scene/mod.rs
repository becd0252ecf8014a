//! The scene on the GPU, shared by every pass and frame: meshes, meshlets, the object,
//! spot-cone and directional-light buffers, the scene's textures (set 1 of every shading
//! pipeline: the sky and material maps, and what the scene's other parts bind there: the
//! environment's maps, the shadow stores')
//! and each object's own textures (set 2).

pub mod meshlets;
pub mod object_data;
pub mod object_textures;
pub mod textures;

use crate::descriptors::Resource;
use crate::error::RenderError;
use crate::gpu_mesh::SceneMeshes;
use crate::scene::meshlets::{storage_buffer_with, MeshletGeometry, MeshletGeometryView};
use crate::scene::object_data::{object_data, SurfaceVariant};
use crate::scene::object_textures::ObjectTextureSets;
use crate::scene::textures::SceneTextures;
use crate::sync::BufferName;
use ml_cpu::alpha_mask::AlphaMasks;
use ml_cpu::gpu_types::{DirectionalLightData, LightCone, ObjectData};
use ml_cpu::scene::Scene;
use ml_vk::{release_on_error, vk, Buffer, Context};

/// The scene's objects (ObjectData), under their shader block's name.
pub const OBJECTS: BufferName = BufferName("ObjectBuffer");
/// The scene's alpha masks' block bounds (common/alpha_mask.glsl), under their block's name.
pub const ALPHA_MASKS: BufferName = BufferName("AlphaMaskBuffer");

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
    pub object_textures: ObjectTextureSets,
    /// The scene's meshlets, built once for every pass that draws them (the visibility
    /// technique, the compute shadow rasters of the point lights and the sun); None where
    /// the settings have no such pass.
    meshlets: Option<MeshletGeometry>,
    wants_meshlets: bool,
}

impl SceneGpu {
    /// The scene's GPU resources as `config` asks; set 1 binds, besides the scene's own
    /// textures, what `set_one` names (the scene's parts: `scene_part`).
    pub fn new(
        ctx: &Context,
        scene: &Scene,
        config: SceneConfig,
        set_one: &dyn Fn(&str) -> Option<Resource>,
    ) -> Result<SceneGpu, RenderError> {
        // Each of these needs the ones before it; a failure releases those.
        let mut textures = SceneTextures::new(ctx, config.material_maps, set_one)?;
        let made = ObjectTextureSets::new(ctx, &scene.textures, &scene.objects);
        let object_textures = release_on_error(ctx, made, &mut [&mut textures])?;
        let mut gpu = SceneGpu {
            meshes: SceneMeshes::empty(),
            objects: Buffer::null(),
            cones: Buffer::null(),
            directional: Buffer::null(),
            alpha_masks: Buffer::null(),
            surface_variants: SurfaceVariant::needed(&scene.objects),
            textures,
            object_textures,
            meshlets: None,
            wants_meshlets: config.meshlets,
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

    /// The scene's objects on the GPU: its meshes, the object buffer and its meshlets (the
    /// shadow stores take their casters from them: `ShadowStores::casters_changed`).
    fn upload_objects(&mut self, ctx: &Context, scene: &Scene) -> Result<(), RenderError> {
        self.meshes = SceneMeshes::upload(ctx, scene)?;
        let masks = AlphaMasks::pack(scene).map_err(|e| RenderError::Invalid(e.to_string()))?;
        self.alpha_masks = storage_buffer_with(ctx, "alpha masks", bytemuck::cast_slice(&masks.words))?;
        let objects: Vec<ObjectData> = scene.objects.iter().map(|o| object_data(o, &masks, &scene.textures)).collect();
        self.objects = Buffer::device_local_with(ctx, "objects", bytemuck::cast_slice(&objects), vk::BufferUsageFlags::STORAGE_BUFFER)?;
        if self.wants_meshlets {
            self.meshlets = Some(MeshletGeometry::build(ctx, scene, &self.object_textures.set_index)?);
        }
        Ok(())
    }

    /// Draw `scene`'s objects from now on (no frame in flight): new meshes, object buffer and
    /// meshlets (the shadow stores then draw their casters again). Only for scenes without object textures (every object binds the one
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
    }

    /// The scene's buffers that shaders bind, under their blocks' names (a frame's table of
    /// resources holds them).
    pub fn named_buffers(&self) -> Vec<(BufferName, vk::Buffer)> {
        vec![
            (OBJECTS, self.objects.raw),
            (BufferName("LightConeBuffer"), self.cones.raw),
            (BufferName("DirectionalLightBuffer"), self.directional.raw),
            (ALPHA_MASKS, self.alpha_masks.raw),
        ]
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
        self.object_textures.destroy(ctx);
    }
}

/// What the scene's GPU resources are made for (the render settings' `scene_config`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneConfig {
    /// The blinn-phong model's albedo and normal maps and sky (else 1×1 stand-ins).
    pub material_maps: bool,
    /// Whether a pass draws the scene's meshlets.
    pub meshlets: bool,
}

impl ml_vk::Release for SceneGpu {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
