//! Scenes: objects (a mesh, an object-to-world transform, a material); lights; a camera.

use crate::blinn_phong::BlinnPhongLights;
use crate::camera::Camera;
use crate::gpu_types::{LightCone, PointLight};
use crate::lights::{LightFrame, LightLayout, LightParams};
use crate::limits::MAX_LIGHT_MARKERS;
use crate::material::Material;
use crate::mesh::{Mesh, MeshKind};
use crate::surface_sampler::SurfaceSampler;
use crate::textures::TextureImage;
use crate::SceneError;
use glam::{Mat4, Quat, Vec3};
use std::collections::HashMap;

/// The seed's ambient factor: colour = albedo · 0.02 + Lo.
pub const SEED_AMBIENT: f32 = 0.02;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Object {
    pub mesh: MeshKind,
    /// Object space → world (any affine transform: glTF nodes rotate and scale unevenly).
    pub transform: Mat4,
    pub material: Material,
    pub textures: ObjectTextures,
    pub extras: MaterialExtras,
}

/// An object's own textures (indices into `Scene::textures`), sampled with its first texture
/// coordinates; glTF's metallic-roughness material.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ObjectTextures {
    /// Multiplies the material's albedo (sRGB).
    pub base_color: Option<u32>,
    /// Tangent-space normal map (n·0.5 + 0.5).
    pub normal: Option<u32>,
    /// Green multiplies the roughness, blue the metallic (linear).
    pub metallic_roughness: Option<u32>,
    /// Red: how much ambient light reaches the point (linear).
    pub occlusion: Option<u32>,
    /// Multiplies `MaterialExtras::emissive` (sRGB).
    pub emissive: Option<u32>,
    /// The extensions' textures (`MaterialLobes`), each multiplying its factor (linear but
    /// where said): the clear coat's strength (red) and roughness (green) and its own normal
    /// map (without one the coat follows the mesh's normal, not the base's map).
    pub clearcoat: Option<u32>,
    pub clearcoat_roughness: Option<u32>,
    pub clearcoat_normal: Option<u32>,
    /// The sheen's colour (sRGB) and roughness (alpha).
    pub sheen_color: Option<u32>,
    pub sheen_roughness: Option<u32>,
    /// The dielectric's specular strength (alpha) and colour (sRGB).
    pub specular: Option<u32>,
    pub specular_color: Option<u32>,
    /// Transmission (red) and the volume's thickness (green).
    pub transmission: Option<u32>,
    pub thickness: Option<u32>,
}

/// Number of texture slots of an object (`ObjectTextures::slots`).
pub const TEXTURE_SLOTS: usize = 14;

/// The slots of the extensions' textures, from the clear coat's on (`ObjectTextures::slots`).
pub const FIRST_LOBE_SLOT: usize = 5;

impl ObjectTextures {
    /// The slots in binding order (object_textures.rs, surface.glsl): base colour, normal,
    /// metallic-roughness, occlusion, emissive, then the extensions' (FIRST_LOBE_SLOT on):
    /// clear coat, its roughness, its normal, sheen colour, sheen roughness, specular,
    /// specular colour, transmission, thickness.
    pub fn slots(&self) -> [Option<u32>; TEXTURE_SLOTS] {
        [
            self.base_color,
            self.normal,
            self.metallic_roughness,
            self.occlusion,
            self.emissive,
            self.clearcoat,
            self.clearcoat_roughness,
            self.clearcoat_normal,
            self.sheen_color,
            self.sheen_roughness,
            self.specular,
            self.specular_color,
            self.transmission,
            self.thickness,
        ]
    }

    /// Whether any of the extensions' textures is there.
    pub fn any_lobe_texture(&self) -> bool {
        self.slots()[FIRST_LOBE_SLOT..].iter().any(Option::is_some)
    }

    /// Bit i set where slot i holds a texture (what the shaders test).
    pub fn bits(&self) -> u32 {
        self.slots().iter().enumerate().map(|(i, s)| u32::from(s.is_some()) << i).sum()
    }

    /// Every texture index changed by `f`.
    pub fn map(self, f: impl Fn(u32) -> u32) -> ObjectTextures {
        ObjectTextures::from_slots(self.slots().map(|s| s.map(&f)))
    }

    /// The textures of `slots`, in `slots`' order.
    pub fn from_slots(slots: [Option<u32>; TEXTURE_SLOTS]) -> ObjectTextures {
        let [base_color, normal, metallic_roughness, occlusion, emissive, clearcoat, clearcoat_roughness, clearcoat_normal, sheen_color, sheen_roughness, specular, specular_color, transmission, thickness] =
            slots;
        ObjectTextures {
            base_color,
            normal,
            metallic_roughness,
            occlusion,
            emissive,
            clearcoat,
            clearcoat_roughness,
            clearcoat_normal,
            sheen_color,
            sheen_roughness,
            specular,
            specular_color,
            transmission,
            thickness,
        }
    }
}

/// A glTF material's factors beyond the seed's albedo, roughness and metallic.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialExtras {
    /// Light the surface gives off itself (linear), added to every model's result.
    pub emissive: Vec3,
    /// Scales the normal map's tangent-space x and y.
    pub normal_scale: f32,
    /// How much of the occlusion texture applies: 1 + strength · (texel − 1).
    pub occlusion_strength: f32,
    /// What the surface's alpha (`base_alpha` × the base colour texture's alpha) does.
    pub alpha_mode: AlphaMode,
    /// The base colour factor's alpha.
    pub base_alpha: f32,
    /// Drawn from both sides, the normal turned toward the viewer (else back faces are culled).
    pub double_sided: bool,
    /// Maps the mesh's texture coordinates to the textures' (glTF's KHR_texture_transform):
    /// one for all of the object's textures and its alpha mask.
    pub uv_transform: glam::Affine2,
    /// What glTF's PBR extensions add (pbr model).
    pub lobes: crate::material_lobes::MaterialLobes,
}

impl Default for MaterialExtras {
    fn default() -> MaterialExtras {
        MaterialExtras {
            emissive: Vec3::ZERO,
            normal_scale: 1.0,
            occlusion_strength: 1.0,
            alpha_mode: AlphaMode::Opaque,
            base_alpha: 1.0,
            double_sided: false,
            uv_transform: glam::Affine2::IDENTITY,
            lobes: Default::default(),
        }
    }
}

impl MaterialExtras {
    /// Whether an alpha mask cuts points out of the surface (MASK, and BLEND where it is drawn
    /// as a mask: in shadows, and in renders that do not blend it).
    pub fn masked(&self) -> bool {
        self.alpha_mode.cutoff().is_some()
    }

    /// Whether what lies behind shows through it: BLEND, or a material that transmits light
    /// (KHR_materials_transmission, whatever its alpha mode). Such surfaces are blended in the
    /// transparent layers where those are on, and drawn as the other surfaces where not.
    pub fn transparent(&self) -> bool {
        self.alpha_mode == AlphaMode::Blend || self.lobes.transmission > 0.0
    }

    /// Whether its points of alpha 1 let nothing through: BLEND transmitting nothing, its
    /// alpha factor 1 (a point's alpha is the factor times its texture's).
    /// Blending such a point hides what lies behind it, so a renderer may draw those points as
    /// opaque (its "core") and blend only the rest.
    pub fn has_core(&self) -> bool {
        self.alpha_mode == AlphaMode::Blend && self.lobes.transmission == 0.0 && self.base_alpha >= 1.0
    }
}

/// glTF's alpha modes: what a surface's alpha does to its pixels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: every pixel of the surface is drawn.
    Opaque,
    /// Cut-outs (foliage, fences, grates): a point whose alpha is below `cutoff` is not there
    /// at all — not drawn, not in any depth, casts no shadow.
    Mask { cutoff: f32 },
    /// Transparency: blended over what lies behind by its alpha, in per-pixel layers
    /// (`transparency`); shadows, and renders with transparency off, take it as a mask at
    /// `BLEND_AS_MASK_CUTOFF`.
    Blend,
}

/// The cutoff a blended material is drawn (and casts shadows) with as a mask.
pub const BLEND_AS_MASK_CUTOFF: f32 = 0.5;

impl AlphaMode {
    /// The alpha below which a point is dropped, if any is.
    pub fn cutoff(self) -> Option<f32> {
        match self {
            AlphaMode::Opaque => None,
            AlphaMode::Mask { cutoff } => Some(cutoff),
            AlphaMode::Blend => Some(BLEND_AS_MASK_CUTOFF),
        }
    }
}

impl Object {
    /// `mesh` scaled by `scale` about its origin, then moved to `position`.
    pub fn placed(mesh: MeshKind, position: Vec3, scale: f32, material: Material) -> Object {
        let transform = Mat4::from_scale_rotation_translation(Vec3::splat(scale), Quat::IDENTITY, position);
        Object { mesh, transform, material, textures: ObjectTextures::default(), extras: MaterialExtras::default() }
    }

    /// Where its origin lands.
    pub fn position(&self) -> Vec3 {
        self.transform.w_axis.truncate()
    }

    /// World box around it, its mesh taken as the cube [−1, 1]³ (every built-in mesh fits it).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let centre = self.position();
        // |M|·(1, 1, 1): the half-extent of the transformed cube along each world axis.
        let m = glam::Mat3::from_mat4(self.transform);
        let half = m.x_axis.abs() + m.y_axis.abs() + m.z_axis.abs();
        (centre - half, centre + half)
    }

    /// A sphere around it (centre, radius).
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let (lo, hi) = self.bounds();
        ((lo + hi) * 0.5, (hi - lo).length() * 0.5)
    }

    /// (position, scale) if it is only moved and scaled evenly (no rotation, no shear).
    pub fn as_placed(&self) -> Option<(Vec3, f32)> {
        let m = glam::Mat3::from_mat4(self.transform);
        let s = m.x_axis.x;
        let even = glam::Mat3::from_diagonal(Vec3::splat(s));
        (m.abs_diff_eq(even, 0.0) && self.transform.row(3) == glam::Vec4::W).then_some((self.position(), s))
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    pub objects: Vec<Object>,
    /// Lights at rest; the renderer animates them per frame.
    pub lights: Vec<PointLight>,
    /// How far the lights move in the seed's animation (`lights::SEED_MOTION`, or for lights
    /// fitted to the scene `LightFrame::motion`).
    pub light_motion: f32,
    pub camera: Camera,
    /// Whether `camera` is the one framing the scene for a default-sized image (a file without
    /// a camera of its own): a render of another aspect frames the scene again for its own.
    pub camera_framed: bool,
    pub ambient: f32,
    /// The other lights of the blinn-phong model (the seed model ignores them).
    pub blinn_phong: BlinnPhongLights,
    /// Meshes of the scene's own (glTF), drawn by objects of kind `MeshKind::Loaded(index)`;
    /// each fits [−1, 1]³ like the built-in ones (the loader folds its box into the objects'
    /// transforms).
    pub meshes: Vec<Mesh>,
    /// Textures of the scene's own (glTF), named by `Object::textures`.
    pub textures: Vec<TextureImage>,
    /// Lights infinitely far away (glTF, scene files): any number up to MAX_DIRECTIONAL_LIGHTS.
    pub directional: Vec<DirectionalLight>,
    /// Spot cones, one per light (LightCone::NONE for point lights) — or none at all in a
    /// scene without spot lights.
    pub cones: Vec<LightCone>,
    /// What the features add to the scene, by type (`scene_section`): the environment light
    /// (the pbr model; none: the constant ambient).
    pub sections: crate::scene_section::Sections,
}

/// A light marker's half-width as a fraction of its light's radius (the seed's radius-15
/// lights get cubes 0.6 m wide beside spheres 2 m wide).
pub const LIGHT_MARKER_SIZE: f32 = 0.02;

/// Most directional lights a scene may have: every point sums them all (they reach everywhere,
/// so no culling helps), so this is a bound on absurd files, not on the buffer they lie in.
pub const MAX_DIRECTIONAL_LIGHTS: usize = 65_536;

/// A light infinitely far away: the same everywhere, from one direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionalLight {
    /// Unit direction the light travels.
    pub direction: Vec3,
    /// Linear colour × strength.
    pub color: Vec3,
}

impl Scene {
    /// Whether some object is transparent (`MaterialExtras::transparent`: BLEND or
    /// transmission).
    pub fn has_transparent_objects(&self) -> bool {
        self.objects.iter().any(|o| o.extras.transparent())
    }

    /// Whether some object's PBR extensions vary over its surface: textures of theirs, or a
    /// clear coat over a normal map (the coat keeps the mesh's normal, the base takes the
    /// map's), so the lighting needs them per point, not per object.
    pub fn has_lobe_textures(&self) -> bool {
        self.objects.iter().any(|o| o.textures.any_lobe_texture() || (o.extras.lobes.clearcoat > 0.0 && o.textures.normal.is_some()))
    }

    /// The built-in `seed` scene (docs/DESIGN.md#the-seed-scene): a 7×7 grid of one object kind at
    /// x,z = (i − 3.5)·2.5, y = 0, in one material.
    pub fn seed(mesh: MeshKind, material: Material, lights: &LightParams) -> Result<Scene, SceneError> {
        let mut scene = Scene::seed_objects(mesh, material);
        scene.lights = scene.build_lights(lights, &LightFrame::BUILT_IN)?;
        Ok(scene)
    }

    /// The seed scene's 7×7 objects and camera, without lights.
    pub fn seed_objects(mesh: MeshKind, material: Material) -> Scene {
        let mut objects = Vec::with_capacity(49);
        for i in 0..7 {
            for j in 0..7 {
                let at = |k: i32| (k as f32 - 3.5) * 2.5;
                objects.push(Object::placed(mesh, Vec3::new(at(i), 0.0, at(j)), 1.0, material));
            }
        }
        Scene::new(objects, Vec::new(), Camera::seed())
    }

    /// `objects` lit by point `lights` and the seed's ambient, seen by `camera`; the
    /// blinn-phong model's default lights; no meshes, textures, spot or directional lights of
    /// its own.
    pub fn new(objects: Vec<Object>, lights: Vec<PointLight>, camera: Camera) -> Scene {
        Scene {
            objects,
            lights,
            light_motion: crate::lights::SEED_MOTION,
            camera,
            camera_framed: false,
            ambient: SEED_AMBIENT,
            blinn_phong: BlinnPhongLights::default(),
            meshes: Vec::new(),
            textures: Vec::new(),
            directional: Vec::new(),
            cones: Vec::new(),
            sections: Default::default(),
        }
    }

    /// The seed scene as the blinn-phong model shows it: the same grid standing on a floor (which
    /// receives the sun's shadows), for the blinn-phong model.
    pub fn with_floor(mut self) -> Scene {
        let floor = Material { albedo: Vec3::splat(0.8), roughness: 0.7, metallic: 0.0 };
        let (lo, hi) = self.bounds();
        let centre = (lo + hi) * 0.5;
        let half = (hi - lo).max_element() * 0.5 + 2.0;
        self.objects.push(Object::placed(MeshKind::Plane, Vec3::new(centre.x, lo.y, centre.z), half, floor));
        self
    }

    /// The point-light shadow scene (`--scene room`): a closed room 10 m across, a
    /// 1×3×1 m pillar of three cubes on its floor, one white point light reaching every
    /// corner, a camera in a corner looking past the pillar. For the lit shading models
    /// (pbr, blinn-phong): the seed model's walls show little besides highlights.
    pub fn shadow_room() -> Scene {
        let walls = Material { albedo: Vec3::new(0.8, 0.78, 0.75), roughness: 0.8, metallic: 0.0 };
        let stone = Material { albedo: Vec3::new(0.7, 0.3, 0.2), roughness: 0.6, metallic: 0.0 };
        let mut objects = vec![Object::placed(MeshKind::Room, Vec3::ZERO, 5.0, walls)];
        for level in 0..3 {
            objects.push(Object::placed(MeshKind::Cube, Vec3::new(1.5, -4.5 + level as f32, 0.5), 0.5, stone));
        }
        // Below the pillar's top, so its shadow crosses the floor and climbs the far wall.
        let light = PointLight { position_radius: [-1.5, -2.5, -1.5, 20.0], color: [3.0, 3.0, 3.0, 0.0] };
        let camera = Camera::looking_at(Vec3::new(-4.2, 2.5, -4.0), Vec3::new(2.0, -3.0, 2.0), 75.0, 0.05, 50.0);
        Scene::new(objects, vec![light], camera)
    }

    /// The scene with every point light drawn (`--show-lights`): a small cube at the light's
    /// rest place, half as wide as LIGHT_MARKER_SIZE of its radius, black and glowing in the
    /// light's colour (emission, which every model adds as it is and every technique draws).
    /// Ordinary objects, so every technique depth-tests them like the rest of the scene.
    pub fn with_light_markers(mut self) -> Result<Scene, SceneError> {
        if self.lights.len() > MAX_LIGHT_MARKERS {
            return Err(SceneError::TooManyMarkers(self.lights.len()));
        }
        let black = Material { albedo: Vec3::ZERO, roughness: 1.0, metallic: 0.0 };
        let markers = self.lights.iter().map(|l| {
            let [x, y, z, radius] = l.position_radius;
            let extras = MaterialExtras { emissive: Vec3::from_slice(&l.color[..3]), ..MaterialExtras::default() };
            Object { extras, ..Object::placed(MeshKind::Cube, Vec3::new(x, y, z), radius * LIGHT_MARKER_SIZE, black) }
        });
        self.objects.extend(markers.collect::<Vec<_>>());
        Ok(self)
    }

    /// World box around every object (each mesh fits [−1, 1]³ in object space).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        self.objects.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), o| {
            let (a, b) = o.bounds();
            (lo.min(a), hi.max(b))
        })
    }

    /// The vertices and indices of `kind`: built in, or one of the scene's own.
    pub fn mesh(&self, kind: MeshKind) -> Option<Mesh> {
        match kind {
            MeshKind::Loaded(i) => self.meshes.get(i as usize).cloned(),
            builtin => Some(builtin.build()),
        }
    }

    /// Its surfaces to draw points from (the surface light layout): every triangle of every
    /// object in world space; None when they have no area at all.
    pub fn surfaces(&self) -> Option<SurfaceSampler> {
        // Each mesh built (or cloned) once, however many objects draw it.
        let mut meshes = HashMap::new();
        for o in &self.objects {
            meshes.entry(o.mesh).or_insert_with(|| self.mesh(o.mesh).unwrap_or_default());
        }
        SurfaceSampler::new(self.objects.iter().map(|o| (&meshes[&o.mesh], o.transform)))
    }

    /// The lights `params` asks for, at rest in `frame` over this scene's objects (whose
    /// surfaces the surface layout draws from). A method of the scene, not of `LightParams`:
    /// scenes hold lights, so lights.rs takes no scene (the two modules would import each other).
    pub fn build_lights(&self, params: &LightParams, frame: &LightFrame) -> Result<Vec<PointLight>, SceneError> {
        let surfaces = if params.layout == LightLayout::Surface { self.surfaces() } else { None };
        params.build_in(frame, surfaces.as_ref())
    }

    /// The distinct meshes this scene draws, in first-use order.
    pub fn mesh_kinds(&self) -> Vec<MeshKind> {
        // A set beside the list: a scene may hold as many meshes as objects.
        let mut seen = std::collections::HashSet::new();
        self.objects.iter().map(|o| o.mesh).filter(|&kind| seen.insert(kind)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_scene_is_a_7x7_grid() {
        let s = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
        assert_eq!(s.objects.len(), 49);
        assert_eq!(s.objects[0].position(), Vec3::new(-8.75, 0.0, -8.75));
        assert_eq!(s.objects[48].position(), Vec3::new(6.25, 0.0, 6.25));
        assert_eq!(s.objects[0].as_placed(), Some((Vec3::new(-8.75, 0.0, -8.75), 1.0)));
        assert_eq!(s.mesh_kinds(), vec![MeshKind::Sphere]);
        assert_eq!(s.lights.len(), 64);
    }

    #[test]
    fn a_turned_object_has_a_box_around_its_turned_mesh() {
        let white = Material::named("white").unwrap();
        let mut o = Object::placed(MeshKind::Cube, Vec3::new(1.0, 2.0, 3.0), 2.0, white);
        assert_eq!(o.bounds(), (Vec3::new(-1.0, 0.0, 1.0), Vec3::new(3.0, 4.0, 5.0)));
        o.transform = Mat4::from_translation(Vec3::X) * Mat4::from_rotation_y(std::f32::consts::FRAC_PI_4);
        let (lo, hi) = o.bounds();
        let r = std::f32::consts::SQRT_2;
        assert!(
            (lo - Vec3::new(1.0 - r, -1.0, -r)).abs().max_element() < 1e-5 && (hi - Vec3::new(1.0 + r, 1.0, r)).abs().max_element() < 1e-5
        );
        assert_eq!(o.as_placed(), None);
    }

    #[test]
    fn light_markers_are_glowing_cubes_sized_by_their_radius() {
        let params = LightParams { count: 5, ..LightParams::seed_default() };
        let s = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &params).unwrap();
        let shown = s.clone().with_light_markers().unwrap();
        assert_eq!(shown.objects.len(), 49 + 5);
        for (o, l) in shown.objects[49..].iter().zip(&s.lights) {
            assert_eq!(o.as_placed(), Some((Vec3::from_slice(&l.position_radius[..3]), 15.0 * LIGHT_MARKER_SIZE)));
            assert_eq!((o.mesh, o.extras.emissive, o.material.albedo), (MeshKind::Cube, Vec3::from_slice(&l.color[..3]), Vec3::ZERO));
        }
        let many = LightParams { count: MAX_LIGHT_MARKERS as u32 + 1, ..LightParams::seed_default() };
        let crowded = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &many).unwrap();
        assert_eq!(crowded.with_light_markers(), Err(SceneError::TooManyMarkers(MAX_LIGHT_MARKERS + 1)));
    }
}
