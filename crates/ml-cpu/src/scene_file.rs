//! Scene files (`--scene FILE.toml`): camera, shading, point lights and objects made of the
//! built-in meshes, and the tables of the features with a scene section (`[environment]`,
//! `sections::SECTIONS`), each read by its feature. Every field is optional but `objects`;
//! unknown fields are errors (a typo must not be silently ignored). Everything read is
//! checked — finite numbers, sane ranges, counts and file size limited before anything is
//! allocated — and every problem is one error naming the file and, where the parser knows it,
//! the line.

use crate::camera::{clip_planes_for, Camera, DEFAULT_FOV_Y_DEG};
use crate::file_fields::{finite, intensity, non_negative, positive, unit, within, FieldProblem};
use crate::files::{read_regular, ReadError};
use crate::framing::{frame_scene, framing_distance, DEFAULT_ASPECT};
use crate::gltf_scene::GltfError;
use crate::gpu_types::{LightCone, PointLight};
use crate::lights::SEED_RADIUS;
pub use crate::limits::MAX_OBJECTS;
use crate::limits::{LENGTHS, MAX_COORDINATE, MAX_LIGHTS, SCALES};
use crate::material::Material;
use crate::mesh::MeshKind;
use crate::scene::{DirectionalLight, Object, Scene, MAX_DIRECTIONAL_LIGHTS, SEED_AMBIENT};
pub use crate::scene_load::SceneFile;
use crate::scene_load::{check_draw_work, check_extent, read_reference, DrawWorkError, ExtentError, ReferenceError};
use crate::section_kind::{FileSite, SectionError};
use crate::sections::SECTIONS;
use crate::SceneError;
use glam::Vec3;
use serde::{de, Deserialize, Deserializer};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Largest scene file we read (a million objects fit in well under this).
pub const MAX_FILE_BYTES: u64 = 64 << 20;

/// A scene file that could not be loaded: where, and what is wrong (one line).
#[derive(Debug, Error)]
#[error("scene file '{}': {problem}", path.display())]
pub struct SceneFileError {
    pub path: PathBuf,
    pub problem: SceneFileProblem,
}

/// An entry of a scene file's `[[objects]]` or `[[lights]]`, by its index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Entry {
    Object(usize),
    Light(usize),
}

impl std::fmt::Display for Entry {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Entry::Object(i) => write!(f, "objects[{i}]"),
            Entry::Light(i) => write!(f, "lights[{i}]"),
        }
    }
}

/// What is wrong with a scene file. Fields are named as the file spells them (`what`).
#[derive(Debug, Error)]
pub enum SceneFileProblem {
    #[error(transparent)]
    Read(#[from] ReadError),
    #[error("not UTF-8 text (byte {0})")]
    NotUtf8(usize),
    #[error("{0} bytes is more than the {max} a scene file may have", max = MAX_FILE_BYTES)]
    TooLong(usize),
    /// The TOML does not parse, or does not fit the format (unknown fields, wrong types).
    #[error("{}{message}", line.map_or(String::new(), |l| format!("line {l}: ")))]
    Syntax { line: Option<usize>, message: String },
    #[error("no objects: a scene needs at least one [[objects]] entry")]
    NoObjects,
    #[error("{0} objects is more than the {max} a scene file may hold", max = MAX_OBJECTS)]
    TooManyObjects(usize),
    /// More objects than a scene holds once its glTF objects are read.
    #[error("more than the {max} objects a scene may hold", max = MAX_OBJECTS)]
    TooManyDrawn,
    #[error("{0} lights is more than the {max} a scene may hold", max = MAX_LIGHTS)]
    TooManyLights(usize),
    #[error("{entry}: {problem}")]
    In { entry: Entry, problem: Box<SceneFileProblem> },
    #[error(transparent)]
    Field(#[from] FieldProblem),
    #[error(transparent)]
    Extent(#[from] ExtentError),
    #[error(transparent)]
    DrawWork(#[from] DrawWorkError),
    /// An unknown mesh or material name.
    #[error(transparent)]
    Name(#[from] SceneError),
    #[error("needs a mesh (a built-in name) or a gltf file")]
    NoMesh,
    #[error("give either mesh or gltf, not both")]
    MeshAndGltf,
    #[error("material applies to built-in meshes; a glTF object has its own")]
    GltfMaterial,
    #[error("gltf objects need the scene file's folder (load it from a file)")]
    NoFolder,
    /// A `gltf = "file"` object whose file does not load.
    #[error("'{file}': {problem}")]
    Gltf { file: String, problem: GltfError },
    /// A `gltf = "file"` object whose file is not let read or cannot be.
    #[error("'{file}': {problem}")]
    Reference { file: String, problem: ReferenceError },
    #[error("a point light has no direction or cone (kind = \"spot\" or \"directional\"?)")]
    PointWithDirection,
    /// A light without a field its kind needs ("a spot light needs a direction").
    #[error("a {light} light needs a {field}")]
    Missing { light: &'static str, field: &'static str },
    #[error("direction must not be zero")]
    ZeroDirection,
    #[error("inner_deg {inner} and outer_deg {outer}: need 0 ≤ inner < outer ≤ 90")]
    Cone { inner: f32, outer: f32 },
    #[error("a directional light has no position or radius, only a direction")]
    DirectionalWithPosition,
    #[error("more than {max} directional lights", max = MAX_DIRECTIONAL_LIGHTS)]
    TooManyDirectional,
    #[error("unknown kind '{0}': expected point, spot or directional")]
    UnknownLightKind(String),
    #[error("[camera] fov_y_deg {0} must be at least {min} and below 180", min = crate::limits::MIN_FOV_Y_DEG)]
    FieldOfView(f32),
    #[error("[camera] position and target are the same point: the camera looks nowhere")]
    CameraNowhere,
    #[error("[camera] fov_y_deg and ortho_half_height together: an orthographic camera has no field of view (give one)")]
    OrthographicWithFov,
    #[error("[camera] near {near} must be less than far {far}")]
    NearFar { near: f32, far: f32 },
    #[error("[camera] looks straight up or down, where its yaw is undefined: move target or position sideways")]
    CameraVertical,
    /// A feature's table (`[environment]`) that its feature cannot use.
    #[error("[{table}] {problem}")]
    Section { table: &'static str, problem: Box<SectionError> },
}

impl SceneFileProblem {
    /// This problem, said to be in `entry`.
    fn at(self, entry: Entry) -> SceneFileProblem {
        SceneFileProblem::In { entry, problem: Box::new(self) }
    }
}

type Problem = SceneFileProblem;

/// Three numbers (a position, direction or colour): exactly three, where serde's arrays would
/// let the TOML reader pass over any that follow (a position of 3,000,000 numbers read as its
/// first three).
#[derive(Clone, Copy)]
struct Triple([f32; 3]);

impl<'de> Deserialize<'de> for Triple {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Triple, D::Error> {
        struct Three;
        impl<'de> de::Visitor<'de> for Three {
            type Value = Triple;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an array of exactly 3 numbers")
            }
            fn visit_seq<A: de::SeqAccess<'de>>(self, mut seq: A) -> Result<Triple, A::Error> {
                let mut out = [0.0; 3];
                for (i, slot) in out.iter_mut().enumerate() {
                    *slot = seq.next_element()?.ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                // The fourth is where reading stops: nothing more is read of a longer array.
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::custom("more than 3 numbers: expected an array of exactly 3 numbers"));
                }
                Ok(Triple(out))
            }
        }
        d.deserialize_seq(Three)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileScene {
    camera: Option<FileCamera>,
    shading: Option<FileShading>,
    #[serde(default)]
    lights: Vec<FileLight>,
    objects: Vec<FileObject>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileCamera {
    position: Option<Triple>,
    target: Option<Triple>,
    fov_y_deg: Option<f32>,
    /// Makes the camera orthographic: world units seen above and below its axis.
    ortho_half_height: Option<f32>,
    near: Option<f32>,
    far: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileShading {
    model: Option<String>,
    ambient: Option<f32>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileLight {
    kind: Option<String>,
    /// Point lights.
    position: Option<Triple>,
    color: Option<Triple>,
    radius: Option<f32>,
    /// Directional and spot lights: where the light travels / points.
    direction: Option<Triple>,
    /// Spot lights: full light within the inner angle of the axis, none beyond the outer
    /// (degrees; defaults 0 and 45, glTF's).
    inner_deg: Option<f32>,
    outer_deg: Option<f32>,
}

/// A light of a scene file, by kind.
enum Light {
    Point(PointLight, LightCone),
    Directional(DirectionalLight),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileObject {
    mesh: Option<String>,
    gltf: Option<String>,
    position: Option<Triple>,
    scale: Option<f32>,
    material: Option<FileMaterial>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FileMaterial {
    /// A built-in material's name (its albedo, roughness and metallic), overridden field by
    /// field by the others.
    name: Option<String>,
    albedo: Option<Triple>,
    roughness: Option<f32>,
    metallic: Option<f32>,
}

/// Read and check the scene file at `path`.
pub fn load(path: &Path) -> Result<SceneFile, SceneFileError> {
    load_with(path, &[])
}

/// `load`, the features' tables named in `replaced` checked but not loaded (the request
/// replaces their sections: `SectionKind::replaces_file`).
pub fn load_with(path: &Path, replaced: &[&str]) -> Result<SceneFile, SceneFileError> {
    let fail = |problem: Problem| SceneFileError { path: path.to_path_buf(), problem };
    let bytes = read_regular(path, MAX_FILE_BYTES).map_err(|e| fail(e.into()))?;
    let text = std::str::from_utf8(&bytes).map_err(|e| fail(Problem::NotUtf8(e.valid_up_to())))?;
    parse_in(text, path.parent(), replaced).map_err(fail)
}

/// A scene file's bytes (UTF-8 text), its `gltf` paths relative to `folder` (None: glTF
/// objects are refused); the error is the problem, without the file's name.
pub fn from_bytes(bytes: &[u8], folder: Option<&Path>) -> Result<SceneFile, SceneFileProblem> {
    let text = std::str::from_utf8(bytes).map_err(|e| Problem::NotUtf8(e.valid_up_to()))?;
    parse_in(text, folder, &[])
}

/// Parse scene-file text (glTF objects are refused: they need the file's folder); the error
/// is the problem, without the file's name.
pub fn parse(text: &str) -> Result<SceneFile, SceneFileProblem> {
    parse_in(text, None, &[])
}

/// Parse scene-file text whose `gltf` paths are relative to `base`. The features' tables
/// (`sections::SECTIONS`) are taken out of the document and read by their features, the rest
/// is the format's own; either way the TOML reader's errors know their line.
fn parse_in(text: &str, base: Option<&Path>, replaced: &[&str]) -> Result<SceneFile, Problem> {
    if text.len() as u64 > MAX_FILE_BYTES {
        return Err(Problem::TooLong(text.len()));
    }
    let syntax = |e: toml::de::Error| Problem::Syntax {
        line: e.span().map(|s| text[..s.start.min(text.len())].matches('\n').count() + 1),
        message: e.message().replace('\n', " "),
    };
    let mut document = toml::de::DeTable::parse(text).map_err(syntax)?;
    let tables: Vec<_> = SECTIONS.iter().filter_map(|kind| Some((kind, document.get_mut().remove(kind.table)?))).collect();
    let file = FileScene::deserialize(toml::de::Deserializer::from(document)).map_err(|e| {
        // The fields the format knows, then the features' tables.
        let unknown = e.message().starts_with("unknown field");
        let mut problem = syntax(e);
        if let (true, Problem::Syntax { message, .. }) = (unknown, &mut problem) {
            let tables: Vec<String> = SECTIONS.iter().map(|kind| format!("`{}`", kind.table)).collect();
            message.push_str(&format!(", or a feature's table: {}", tables.join(", ")));
        }
        problem
    })?;
    let mut built = build(file, base)?;
    for (kind, table) in tables {
        let site = FileSite { folder: base, replaced: replaced.contains(&kind.table) };
        let read = (kind.read)(toml::de::ValueDeserializer::from(table), &site).map_err(|problem| match problem {
            SectionError::Format(e) => syntax(e),
            // The field's name says the table.
            SectionError::Field(field) => Problem::Field(field),
            problem => Problem::Section { table: kind.table, problem: Box::new(problem) },
        })?;
        if let Some(section) = read {
            built.scene.sections.insert(section);
        }
    }
    Ok(built)
}

fn build(file: FileScene, base: Option<&Path>) -> Result<SceneFile, Problem> {
    if file.objects.is_empty() {
        return Err(Problem::NoObjects);
    }
    if file.objects.len() > MAX_OBJECTS {
        return Err(Problem::TooManyObjects(file.objects.len()));
    }
    if file.lights.len() as u64 > MAX_LIGHTS {
        return Err(Problem::TooManyLights(file.lights.len()));
    }
    let (mut objects, mut meshes, mut textures, mut warnings) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut loaded_files = HashMap::new();
    for (i, o) in file.objects.iter().enumerate() {
        match &o.gltf {
            Some(gltf) => {
                let loaded =
                    gltf_object(o, gltf, base, (&mut meshes, &mut textures, &mut loaded_files)).map_err(|e| e.at(Entry::Object(i)))?;
                objects.extend(loaded.0);
                warnings.extend(loaded.1.into_iter().map(|w| format!("objects[{i}] ({gltf}): {w}")));
            }
            None => objects.push(object(o).map_err(|e| e.at(Entry::Object(i)))?),
        }
        if objects.len() > MAX_OBJECTS {
            return Err(Problem::TooManyDrawn);
        }
    }
    let (mut lights, mut cones, mut directional) = (Vec::new(), Vec::new(), Vec::new());
    for (i, l) in file.lights.iter().enumerate() {
        match light(l).map_err(|e| e.at(Entry::Light(i)))? {
            Light::Point(p, cone) => {
                lights.push(p);
                cones.push(cone);
            }
            Light::Directional(d) if directional.len() < MAX_DIRECTIONAL_LIGHTS => directional.push(d),
            Light::Directional(_) => return Err(Problem::TooManyDirectional.at(Entry::Light(i))),
        }
    }
    let (shading, ambient) = match &file.shading {
        Some(s) => (s.model.clone(), s.ambient.map(|a| intensity("[shading] ambient", a)).transpose()?),
        None => (None, None),
    };
    let mut scene = Scene {
        ambient: ambient.unwrap_or(SEED_AMBIENT),
        meshes,
        textures,
        directional,
        // Only scenes with a spot keep the cones.
        cones: if cones.iter().all(|c| *c == LightCone::NONE) { Vec::new() } else { cones },
        ..Scene::new(objects, lights, Camera::seed())
    };
    // The camera and the lights fitted to the scene are made from its box.
    check_extent(&scene)?;
    check_draw_work(&scene)?;
    (scene.camera, scene.camera_framed) = camera(file.camera.as_ref(), &scene)?;
    Ok(SceneFile { scene, shading, warnings })
}

/// Three finite numbers.
fn vec3(what: &'static str, Triple(v): Triple) -> Result<Vec3, Problem> {
    for x in v {
        finite(what, x)?;
    }
    Ok(Vec3::from(v))
}

/// A place or a direction: each coordinate within ±MAX_COORDINATE.
fn coordinates(what: &'static str, v: Triple) -> Result<Vec3, Problem> {
    let v = vec3(what, v)?;
    for x in v.to_array() {
        within(what, x, -MAX_COORDINATE..=MAX_COORDINATE)?;
    }
    Ok(v)
}

/// A radius, a clip plane, a half-height: positive, in LENGTHS.
fn length(what: &'static str, value: f32) -> Result<f32, Problem> {
    Ok(within(what, positive(what, value)?, LENGTHS)?)
}

/// An object's scale: positive, in SCALES.
fn scale(value: f32) -> Result<f32, Problem> {
    Ok(within("scale", positive("scale", value)?, SCALES)?)
}

fn object(o: &FileObject) -> Result<Object, Problem> {
    let name = o.mesh.as_ref().ok_or(Problem::NoMesh)?;
    let mesh = MeshKind::from_name(name)?;
    let mut material = Material::named("white").expect("built in");
    if let Some(m) = &o.material {
        if let Some(name) = &m.name {
            material = Material::named(name)?;
        }
        if let Some(a) = m.albedo {
            material.albedo = vec3("material albedo", a)?;
            for x in a.0 {
                unit("material albedo", non_negative("material albedo", x)?)?;
            }
        }
        if let Some(r) = m.roughness {
            material.roughness = unit("material roughness", r)?;
        }
        if let Some(v) = m.metallic {
            material.metallic = unit("material metallic", v)?;
        }
    }
    let (position, scale) = placement(o)?;
    Ok(Object::placed(mesh, position, scale, material))
}

/// An object's position and scale (defaults: the origin, 1).
fn placement(o: &FileObject) -> Result<(Vec3, f32), Problem> {
    let position = o.position.map(|p| coordinates("position", p)).transpose()?.unwrap_or(Vec3::ZERO);
    Ok((position, o.scale.map(scale).transpose()?.unwrap_or(1.0)))
}

/// A `gltf = "path"` object: every drawn primitive of that file, its materials, placed by the
/// object's position and scale; its meshes and textures appended to `meshes` and `textures`
/// the first time the file is placed, and shared by every later placement (`loaded`: per
/// file, its objects before placement): a file placed 800 times is read, decoded and held
/// once. Its warnings come with its first placement. Its lights and camera are not used (the
/// scene file says where lights and camera are).
fn gltf_object(
    o: &FileObject,
    gltf: &str,
    base: Option<&Path>,
    (meshes, textures, loaded): (&mut Vec<crate::mesh::Mesh>, &mut Vec<crate::textures::TextureImage>, &mut LoadedFiles),
) -> Result<(Vec<Object>, Vec<String>), Problem> {
    if o.mesh.is_some() {
        return Err(Problem::MeshAndGltf);
    }
    if o.material.is_some() {
        return Err(Problem::GltfMaterial);
    }
    let base = base.ok_or(Problem::NoFolder)?;
    let (position, scale) = placement(o)?;
    let place = glam::Mat4::from_scale_rotation_translation(Vec3::splat(scale), glam::Quat::IDENTITY, position);
    // A volume's thickness (world units) scales with the placement, as the geometry does.
    let placed = |unplaced: &[Object]| {
        unplaced
            .iter()
            .map(|obj| {
                let mut extras = obj.extras;
                extras.lobes.thickness *= scale;
                Object { transform: place * obj.transform, extras, ..*obj }
            })
            .collect()
    };
    if let Some(unplaced) = loaded.get(gltf) {
        return Ok((placed(unplaced), Vec::new()));
    }
    let bytes = read_reference(base, Path::new(gltf), crate::gltf_scene::MAX_FILE_BYTES)
        .map_err(|problem| Problem::Reference { file: gltf.to_owned(), problem })?;
    // Its buffers and images are named relative to its own folder.
    let folder = base.join(gltf).parent().map(Path::to_path_buf).unwrap_or_default();
    let (scene, warnings) =
        crate::gltf_scene::from_bytes(&bytes, Some(&folder)).map_err(|problem| Problem::Gltf { file: gltf.to_owned(), problem })?;
    let offset = meshes.len() as u32;
    meshes.extend(scene.meshes);
    let texture_offset = textures.len() as u32;
    textures.extend(scene.textures);
    let unplaced: Vec<Object> = scene
        .objects
        .into_iter()
        .map(|obj| {
            let mesh = match obj.mesh {
                MeshKind::Loaded(i) => MeshKind::Loaded(i + offset),
                builtin => builtin,
            };
            Object { mesh, textures: obj.textures.map(|i| i + texture_offset), ..obj }
        })
        .collect();
    let objects = placed(&unplaced);
    loaded.insert(gltf.to_owned(), unplaced);
    Ok((objects, warnings))
}

/// The glTF files a scene file has placed, by the path it names them with: their objects
/// (meshes and textures already in the scene's lists), before placement.
type LoadedFiles = HashMap<String, Vec<Object>>;

fn light(l: &FileLight) -> Result<Light, Problem> {
    let color = l.color.map(|c| vec3("color", c)).transpose()?.unwrap_or(Vec3::ONE);
    for x in color.to_array() {
        intensity("color", x)?;
    }
    match l.kind.as_deref() {
        kind @ (None | Some("point") | Some("spot")) => {
            let spot = kind == Some("spot");
            if !spot && (l.direction.is_some() || l.inner_deg.is_some() || l.outer_deg.is_some()) {
                return Err(Problem::PointWithDirection);
            }
            let p = coordinates("position", l.position.ok_or(Problem::Missing { light: "point or spot", field: "position" })?)?;
            let radius = l.radius.map(|r| length("radius", r)).transpose()?.unwrap_or(SEED_RADIUS);
            let point = PointLight { position_radius: p.extend(radius).to_array(), color: color.extend(0.0).to_array() };
            if !spot {
                return Ok(Light::Point(point, LightCone::NONE));
            }
            let axis = coordinates("direction", l.direction.ok_or(Problem::Missing { light: "spot", field: "direction" })?)?;
            if axis.length() < 1e-6 {
                return Err(Problem::ZeroDirection);
            }
            let inner = finite("inner_deg", l.inner_deg.unwrap_or(0.0))?;
            let outer = finite("outer_deg", l.outer_deg.unwrap_or(45.0))?;
            if !(inner >= 0.0 && inner < outer && outer <= 90.0) {
                return Err(Problem::Cone { inner, outer });
            }
            Ok(Light::Point(point, LightCone::spot(axis, inner.to_radians(), outer.to_radians())))
        }
        Some("directional") => {
            if l.position.is_some() || l.radius.is_some() {
                return Err(Problem::DirectionalWithPosition);
            }
            let d = coordinates("direction", l.direction.ok_or(Problem::Missing { light: "directional", field: "direction" })?)?;
            if d.length() < 1e-6 {
                return Err(Problem::ZeroDirection);
            }
            Ok(Light::Directional(DirectionalLight { direction: d.normalize(), color }))
        }
        Some(kind) => Err(Problem::UnknownLightKind(kind.to_owned())),
    }
}

/// The file's camera; fields it leaves out come from a camera framing every object: without
/// position and target, the one that frames the objects for a default-sized image
/// (`framing::frame_scene`; a render of another aspect frames them again for its own), else
/// looking at the centre of their bounds from above and in front, the whole box in view. And
/// whether it is that framing camera unchanged (`Scene::camera_framed`).
fn camera(c: Option<&FileCamera>, scene: &Scene) -> Result<(Camera, bool), Problem> {
    let (lo, hi) = scene.bounds();
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    if c.is_some_and(|c| c.fov_y_deg.is_some() && c.ortho_half_height.is_some()) {
        return Err(Problem::OrthographicWithFov);
    }
    let fov = match c.and_then(|c| c.fov_y_deg) {
        Some(f) if finite("[camera] fov_y_deg", f)? >= crate::limits::MIN_FOV_Y_DEG && f < 180.0 => f,
        Some(f) => return Err(Problem::FieldOfView(f)),
        None => DEFAULT_FOV_Y_DEG,
    };
    if c.is_none_or(|c| c.position.is_none() && c.target.is_none()) {
        let framed = frame_scene(scene, DEFAULT_ASPECT, fov);
        let (near, far) = clip_planes(c, (framed.near, framed.far))?;
        let camera = Camera { near, far, orthographic: orthographic(c)?, ..framed };
        return Ok((camera, camera == framed));
    }
    let position = match c.and_then(|c| c.position) {
        Some(p) => coordinates("[camera] position", p)?,
        None => centre + Vec3::new(0.0, 0.5, 1.0).normalize() * framing_distance(radius, fov),
    };
    let target = match c.and_then(|c| c.target) {
        Some(t) => coordinates("[camera] target", t)?,
        None => centre,
    };
    if position.distance(target) < 1e-6 {
        return Err(Problem::CameraNowhere);
    }
    let (near, far) = clip_planes(c, clip_planes_for(lo, hi, position))?;
    let dir = (target - position).normalize();
    if dir.y.abs() > 0.9999 {
        return Err(Problem::CameraVertical);
    }
    Ok((Camera { orthographic: orthographic(c)?, ..Camera::looking_at(position, target, fov, near, far) }, false))
}

/// The camera's near and far planes: the file's, else `fitted`; near before far.
fn clip_planes(c: Option<&FileCamera>, (fitted_near, fitted_far): (f32, f32)) -> Result<(f32, f32), Problem> {
    let near = c.and_then(|c| c.near).map(|n| length("[camera] near", n)).transpose()?.unwrap_or(fitted_near);
    let far = c.and_then(|c| c.far).map(|f| length("[camera] far", f)).transpose()?.unwrap_or(fitted_far);
    if near >= far {
        return Err(Problem::NearFar { near, far });
    }
    Ok((near, far))
}

/// The file's orthographic half-height, if it makes the camera orthographic.
fn orthographic(c: Option<&FileCamera>) -> Result<Option<f32>, Problem> {
    c.and_then(|c| c.ortho_half_height).map(|h| length("[camera] ortho_half_height", h)).transpose()
}

/// `scene` as a scene file (built-in meshes only), every field written out: what `load` reads
/// back into the same scene (up to the camera, given as position + target).
pub fn to_toml(scene: &Scene, shading: &str, target: Vec3) -> String {
    let v = |v: Vec3| format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z);
    let c = &scene.camera;
    // An orthographic camera's half-height, a perspective one's field of view.
    let lens = match c.orthographic {
        Some(h) => format!("ortho_half_height = {h:?}\n"),
        None => format!("fov_y_deg = {:?}\n", c.fov_y_deg),
    };
    let mut out = format!(
        "[camera]\nposition = {}\ntarget = {}\n{lens}near = {:?}\nfar = {:?}\n\n[shading]\nmodel = \"{shading}\"\nambient = {:?}\n",
        v(c.position),
        v(target),
        c.near,
        c.far,
        scene.ambient
    );
    for (i, l) in scene.lights.iter().enumerate() {
        let p = l.position_radius;
        out += &format!(
            "\n[[lights]]\nposition = {}\ncolor = {}\nradius = {:?}\n",
            v(Vec3::new(p[0], p[1], p[2])),
            v(Vec3::new(l.color[0], l.color[1], l.color[2])),
            p[3]
        );
        if let Some(c) = scene.cones.get(i).filter(|c| **c != LightCone::NONE) {
            // Back from scale = 1 / (cos inner − cos outer), offset = −cos outer · scale.
            let (scale, axis) = (c.direction_scale[3], Vec3::from_slice(&c.direction_scale[..3]));
            let cos_outer = -c.offset[0] / scale;
            let cos_inner = cos_outer + 1.0 / scale;
            out += &format!(
                "kind = \"spot\"\ndirection = {}\ninner_deg = {:?}\nouter_deg = {:?}\n",
                v(axis),
                cos_inner.clamp(-1.0, 1.0).acos().to_degrees(),
                cos_outer.clamp(-1.0, 1.0).acos().to_degrees()
            );
        }
    }
    for d in &scene.directional {
        out += &format!("\n[[lights]]\nkind = \"directional\"\ndirection = {}\ncolor = {}\n", v(d.direction), v(d.color));
    }
    for o in &scene.objects {
        let m = &o.material;
        // Scene files place objects by position and scale only (rotations: not yet).
        let (position, scale) = o.as_placed().expect("a moved and evenly scaled object");
        out += &format!(
            "\n[[objects]]\nmesh = \"{}\"\nposition = {}\nscale = {:?}\nmaterial = {{ albedo = {}, roughness = {:?}, metallic = {:?} }}\n",
            o.mesh.name(),
            v(position),
            scale,
            v(m.albedo),
            m.roughness,
            m.metallic
        );
    }
    out
}

#[cfg(test)]
mod tests;
