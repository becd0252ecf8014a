//! glTF 2.0 scenes (`--scene FILE.gltf|FILE.glb`): the node hierarchy with its
//! transforms, every triangle primitive (indexed or not; u8/u16/u32 indices; missing normals
//! computed flat, tangents computed from the texture coordinates), metallic-roughness
//! materials with their textures, the PBR extensions' factors (ior, specular, clearcoat, sheen,
//! unlit: material_extensions), KHR_lights_punctual point, spot and directional lights and the
//! first camera (else a camera framing the scene).
//!
//! The `gltf` crate parses and validates the JSON; everything it hands over unchecked is
//! checked here before it is used or allocated: buffer sources and lengths, accessor bounds
//! and strides (sparse accessors too), index ranges, images, finite numbers, counts. Every
//! problem is one line naming it. Textures (PNG, JPEG; base colour and emissive in sRGB):
//! base colour, normal (with its scale), metallic-roughness, occlusion (with its strength)
//! and emissive, each with its sampler's wrapping and filters; all read with TEXCOORD_0 (a
//! texture naming another set gets a warning). Directional lights: any number up to
//! MAX_DIRECTIONAL_LIGHTS. Cameras: perspective or orthographic.

use crate::camera::Camera;
use crate::error::Number;
use crate::files::{read_regular, ReadError};
use crate::gpu_types::{LightCone, PointLight};
use crate::limits::{LENGTHS, MAX_COORDINATE, MAX_INTENSITY, MAX_OBJECTS, SCALES};
use crate::material::Material;
use crate::mesh::{compute_tangents, Mesh, MeshKind, Vertex};
use crate::scene::{
    AlphaMode, DirectionalLight, MaterialExtras, Object, ObjectTextures, Scene, FIRST_LOBE_SLOT, MAX_DIRECTIONAL_LIGHTS, TEXTURE_SLOTS,
};
use crate::scene_load::{check_draw_work, check_extent, read_reference, DrawWorkError, ExtentError, ReferenceError, SceneFile};
use crate::textures::{Filter, TextureImage, TextureSampler, Wrap};
use crate::twin_faces;
use base64::Engine as _;
use glam::{Affine2, Mat3, Mat4, Vec3, Vec4};
use gltf::accessor::{DataType, Dimensions};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Largest glTF or GLB file, and largest buffer (all of a file's buffers together too), we read.
pub const MAX_FILE_BYTES: u64 = 1 << 30;
/// Largest image file (PNG or JPEG) a glTF may name; the decoded image is capped apart
/// (MAX_TEXTURE_SIZE, and 1 GiB of memory).
pub const MAX_IMAGE_BYTES: u64 = 256 << 20;
/// How much longer than its byteLength a buffer's data may be: the padding that ends a GLB's
/// binary chunk at a multiple of 4 bytes.
const BUFFER_PADDING: u64 = 3;
/// Most vertices (after un-indexing for flat normals) and triangles of a whole scene.
pub const MAX_VERTICES: usize = 1 << 26;
/// Widest and tallest texture we decode.
pub const MAX_TEXTURE_SIZE: u32 = 16384;
/// Most bytes a file's textures may take decoded, their mip chains included (RGBA8, 4/3 of
/// the largest level): checked from each image's header before it is decoded, so a small file
/// of huge images is refused in one line instead of taking the machine's memory.
pub const MAX_TEXTURE_BYTES: u64 = 4 << 30;
/// Most elements of an accessor without a buffer view (zeros but for its sparse
/// substitutions): its count is all a few bytes of JSON would need to claim gigabytes.
pub const MAX_VIEWLESS_ELEMENTS: usize = 1 << 20;
/// Deepest node hierarchy we follow.
pub const MAX_NODE_DEPTH: usize = 256;
/// Extensions we read (a file may require these; others it may only use, with a warning), with
/// the material extensions of material_extensions::EXTENSIONS.
const SUPPORTED_EXTENSIONS: [&str; 5] =
    ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_variants", "KHR_mesh_quantization", "KHR_texture_transform"];

fn supported(extension: &str) -> bool {
    SUPPORTED_EXTENSIONS.contains(&extension) || material_extensions::EXTENSIONS.contains(&extension)
}

/// A glTF file that could not be loaded: where, and what is wrong (one line).
#[derive(Debug, Error)]
#[error("glTF file '{}': {problem}", path.display())]
pub struct GltfFileError {
    pub path: PathBuf,
    pub problem: GltfError,
}

/// The part of a glTF file a problem is in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Part {
    Buffer(usize),
    Primitive {
        mesh: usize,
        primitive: usize,
    },
    Light(usize),
    Camera(usize),
    Image(usize),
    /// One of a material's textures ("base colour", "normal", …); material None: glTF's
    /// default material.
    Texture {
        material: Option<usize>,
        slot: &'static str,
    },
    /// The data an accessor or buffer view holds: POSITION, NORMAL, TEXCOORD_0, indices, an
    /// image's bytes.
    Data(&'static str),
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self {
            Part::Buffer(i) => write!(f, "buffer {i}"),
            Part::Primitive { mesh, primitive } => write!(f, "mesh {mesh} primitive {primitive}"),
            Part::Light(i) => write!(f, "light {i}"),
            Part::Camera(i) => write!(f, "camera {i}"),
            Part::Image(i) => write!(f, "image {i}"),
            Part::Texture { material, slot } => write!(f, "material {} {slot} texture", MaterialName(*material)),
            Part::Data(what) => f.write_str(what),
        }
    }
}

/// A material by its index, or glTF's default material.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MaterialName(pub Option<usize>);

impl std::fmt::Display for MaterialName {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        match self.0 {
            Some(i) => write!(f, "{i}"),
            None => f.write_str("default"),
        }
    }
}

/// "a number in [a, b]", or "a number not below a" where the range has no upper end.
fn describe_range(range: &std::ops::RangeInclusive<f32>) -> String {
    match *range.end() {
        f32::MAX => format!("a number not below {}", Number(*range.start())),
        end => format!("a number in [{}, {}]", Number(*range.start()), Number(end)),
    }
}

/// A GLB header that cannot be right.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Error)]
pub enum GlbHeader {
    #[error("the GLB header is cut short")]
    CutShort,
    #[error("GLB version {0} (only 2 exists)")]
    Version(u32),
    #[error("the GLB header says {claimed} bytes, the file has {actual}")]
    Length { claimed: u32, actual: usize },
    #[error("GLB chunk {chunk} ({}) says {claimed} bytes, but {left} follow its 8-byte header", chunk_kind(*kind))]
    ChunkLength { chunk: usize, kind: u32, claimed: u32, left: usize },
    #[error("the first GLB chunk is {}, not JSON", chunk_kind(*.0))]
    FirstNotJson(u32),
    #[error("{0} bytes after the last GLB chunk are not a chunk (a chunk is an 8-byte header and its bytes)")]
    Trailing(usize),
}

/// A GLB chunk's type as its four bytes read ("JSON", "BIN" and others as text where they
/// are, else in hex).
fn chunk_kind(kind: u32) -> String {
    let b = kind.to_le_bytes();
    let text: String = b.iter().filter(|&&c| c != 0).map(|&c| c as char).collect();
    if !text.is_empty() && text.chars().all(|c| c.is_ascii_alphanumeric()) {
        text
    } else {
        format!("type 0x{kind:08x}")
    }
}

/// What is wrong with a glTF file.
#[derive(Debug, Error)]
pub enum GltfError {
    #[error(transparent)]
    Read(#[from] ReadError),
    #[error("{part}: {problem}")]
    In { part: Part, problem: Box<GltfError> },
    #[error("the file is empty")]
    Empty,
    #[error("not a readable glTF/GLB file: {0}")]
    Glb(GlbHeader),
    /// What the gltf crate could not parse.
    #[error("not a readable glTF/GLB file: {}", .0.to_string().replace('\n', " "))]
    Unreadable(gltf::Error),
    /// What the gltf crate's validation found: each place (a JSON path) and its error.
    #[error("invalid glTF: {}", describe_invalid(.0))]
    Invalid(Vec<(gltf::json::Path, gltf::json::validation::Error)>),
    #[error("requires extension {0}, which manylights does not support")]
    RequiredExtension(String),
    #[error("the node hierarchy is deeper than {max} (or has a cycle) at node {0}", max = MAX_NODE_DEPTH)]
    TooDeep(usize),
    #[error("node {0} is its own ancestor: glTF's nodes form trees (here no deeper than {max}), without cycles", max = MAX_NODE_DEPTH)]
    Cycle(usize),
    #[error("node {node} is a child of both node {first} and node {second}: glTF's nodes form trees, each node one parent")]
    TwoParents { node: usize, first: usize, second: usize },
    #[error("scene {scene}: node {node} is one of its roots and a child of node {parent}")]
    RootWithParent { scene: usize, node: usize, parent: usize },
    #[error("scene {scene}: node {node} is named twice among its roots")]
    RootTwice { scene: usize, node: usize },
    #[error("asset.version '{0}' is not glTF 2.x")]
    Version(String),
    #[error("asset.minVersion '{0}': manylights reads glTF 2.0")]
    MinVersion(String),
    #[error("node {0}: its transform is not finite")]
    NodeTransform(usize),
    #[error("node {0}: its matrix's last row is not (0, 0, 0, 1) (glTF: a matrix is a translation, rotation and scale)")]
    NodeProjective(usize),
    #[error("node {0}: it has a matrix and a translation, rotation or scale too (glTF: one or the other)")]
    NodeMatrixAndTrs(usize),
    #[error("node {node}: its rotation's length is {}, not 1 (glTF: a unit quaternion, within {ROTATION_LENGTH_TOLERANCE})", Number(*length))]
    NodeRotation { node: usize, length: f32 },
    #[error("node {0}: its transform is singular (it flattens the node to a plane, a line or a point)")]
    NodeSingular(usize),
    #[error("node {node}: its transform scales an axis by {}, outside {} to {}", Number(*scale), Number(*SCALES.start()), Number(*SCALES.end()))]
    NodeScale { node: usize, scale: f32 },
    #[error(transparent)]
    Extent(#[from] ExtentError),
    #[error(transparent)]
    DrawWork(#[from] DrawWorkError),
    #[error("the scene has no triangles to draw")]
    NoTriangles,
    /// A primitive's attribute naming an accessor that does not exist.
    #[error("{attribute} names accessor {accessor}, but there are {accessors}")]
    NoAccessor { attribute: String, accessor: usize, accessors: usize },
    #[error("{claimed} bytes claimed, more than the {max} we read", max = MAX_FILE_BYTES)]
    BufferTooLarge { claimed: u64 },
    #[error("refers to the GLB binary chunk, which the file does not have")]
    NoBinaryChunk,
    #[error("holds {holds} bytes but claims {claims}")]
    BufferShort { holds: usize, claims: u64 },
    #[error("holds {holds} bytes but claims {claims} (more than 3 bytes of padding)")]
    BufferLong { holds: u64, claims: u64 },
    #[error("only the first buffer may be the GLB binary chunk (it has no uri)")]
    BinaryChunkNotFirst,
    #[error("'{0}' is not a valid URI (a % not followed by two hexadecimal digits, or not UTF-8 once decoded)")]
    BadUri(String),
    #[error("a data URI that is not base64")]
    NotBase64,
    #[error("bad base64 data: {0}")]
    Base64(base64::DecodeError),
    #[error("'{0}' is not a local file (manylights never downloads)")]
    Remote(String),
    #[error("external files are not allowed here")]
    NoFolder,
    /// A file the glTF names (a buffer or an image) that is not let read or cannot be.
    #[error("'{reference}': {problem}")]
    External { reference: String, problem: ReferenceError },
    #[error("more than {max} drawn primitives", max = MAX_OBJECTS)]
    TooManyPrimitives,
    #[error("has no POSITION")]
    NoPositions,
    #[error("the scene has more than {max} vertices", max = MAX_VERTICES)]
    TooManyVertices,
    #[error("{attribute} has {entries} entries but POSITION has {positions}")]
    AttributeCount { attribute: &'static str, entries: usize, positions: usize },
    #[error("{0} indices do not make whole triangles")]
    PartialTriangle(usize),
    #[error("{0} elements is more than we read")]
    TooManyElements(usize),
    #[error("stride {stride} is smaller than an element ({element} bytes)")]
    Stride { stride: usize, element: usize },
    #[error("its size overflows")]
    SizeOverflow,
    #[error(
        "{count} elements of {element} bytes (stride {stride}, offset {offset}) need {needed} bytes but buffer view {view} has {length}"
    )]
    ViewTooShort { count: usize, element: usize, stride: usize, offset: usize, needed: usize, view: usize, length: usize },
    #[error("accessor {0} has no buffer view")]
    NoView(usize),
    #[error("{0} elements without a buffer view: more than the {max} such an accessor may have", max = MAX_VIEWLESS_ELEMENTS)]
    TooManyZeros(usize),
    #[error("{substitutions} sparse substitutions for {count} elements")]
    TooManySparse { substitutions: usize, count: usize },
    /// `part`: the sparse "indices" or "values".
    #[error("the sparse {part} ({len} bytes at {offset}) lie outside their buffer view")]
    SparseOutside { part: &'static str, len: usize, offset: usize },
    #[error("sparse index {k} is {index}; they must rise and stay below {count}")]
    SparseIndex { k: usize, index: usize, count: usize },
    #[error("buffer view {view} ({length} bytes at {offset}) lies outside its buffer of {buffer} bytes")]
    ViewOutside { view: usize, length: usize, offset: usize, buffer: usize },
    #[error("expected {expected:?} elements, found {found:?}")]
    Dimensions { expected: Dimensions, found: Dimensions },
    #[error("component type {ty:?} (normalized: {normalized}) is not allowed")]
    ComponentType { ty: DataType, normalized: bool },
    #[error("element {index} is not finite ({value})")]
    NotFinite { index: usize, value: f32 },
    #[error("element {index} is {}, beyond ±{}", Number(*value), Number(MAX_COORDINATE))]
    TooFar { index: usize, value: f32 },
    #[error(
        "byteOffset {offset} (in a buffer view at {view_offset}, stride {stride}) is not a multiple of its components' {component} bytes"
    )]
    Misaligned { offset: usize, view_offset: usize, stride: usize, component: usize },
    #[error("expected scalars, found {0:?}")]
    NotScalar(Dimensions),
    #[error("component type {0:?} is not an index type")]
    NotIndexType(DataType),
    #[error("element {index} is {value}, but there are only {vertices} vertices")]
    IndexOutOfRange { index: usize, value: u32, vertices: usize },
    #[error("material {material}: {factor} factor {value} is outside [0, 1]")]
    Factor { material: MaterialName, factor: &'static str, value: f32 },
    #[error("material {material}: normal scale {value} is not finite")]
    NormalScale { material: MaterialName, value: f32 },
    #[error("material {material}: alphaCutoff {value} must be finite and not negative")]
    AlphaCutoff { material: MaterialName, value: f32 },
    #[error("material {material}: its texture transform is not finite")]
    TextureTransform { material: MaterialName },
    #[error("there is no material variant '{name}' (the file has {})", if known.is_empty() { "none".to_owned() } else { known.join(", ") })]
    UnknownVariant { name: String, known: Vec<String> },
    #[error("a material variant maps it to material {index}, but there are {materials} materials")]
    VariantMaterial { index: u64, materials: usize },
    #[error("material {material}: ior {} must be 0 or from 1 to {}", Number(*value), Number(material_extensions::MAX_IOR))]
    Ior { material: MaterialName, value: f32 },
    #[error("material {material}: {field} is {value}; it must be {}", describe_range(range))]
    ExtensionFactor { material: MaterialName, field: &'static str, value: String, range: std::ops::RangeInclusive<f32> },
    #[error("material {material}: {field} {why}")]
    ExtensionTexture { material: MaterialName, field: &'static str, why: String },
    #[error("material {material}: emissive strength {} must be finite, not negative and at most {}", Number(*value), Number(MAX_INTENSITY))]
    EmissiveStrength { material: MaterialName, value: f32 },
    #[error("its buffer view does not exist")]
    NoImageView,
    #[error("{0} bytes is more than the {max} an image may have", max = MAX_IMAGE_BYTES)]
    ImageTooLarge(usize),
    #[error("a buffer view without a mimeType")]
    NoMimeType,
    #[error("needs either a uri or a bufferView")]
    NoImageSource,
    /// An image whose format cannot be told.
    #[error("{0}")]
    ImageFormat(std::io::Error),
    /// An image in a container manylights does not read (KTX, KTX2, DDS), named.
    #[error("it is a {0} image, which manylights does not read (PNG and JPEG only)")]
    ImageContainer(&'static str),
    #[error("its {width}×{height} texels would take {} MiB decoded, past the {} MiB a file's textures may take together ({} MiB taken before it)", need >> 20, MAX_TEXTURE_BYTES >> 20, taken >> 20)]
    TextureBudget { width: u32, height: u32, need: u64, taken: u64 },
    #[error("cannot decode it: {0}")]
    Decode(image::ImageError),
    #[error("cannot decode it: its decoder stopped on malformed data")]
    DecoderFailed,
    #[error("a directional light needs a usable node direction and a colour × intensity in [0, {}]", Number(MAX_INTENSITY))]
    Directional,
    #[error("more than {max} directional lights", max = MAX_DIRECTIONAL_LIGHTS)]
    TooManyDirectional,
    #[error("spot cone angles inner {inner}, outer {outer}: need 0 ≤ inner < outer ≤ π/2")]
    SpotCone { inner: f32, outer: f32 },
    #[error("its node's transform collapses the spot's direction")]
    SpotDirection,
    #[error("colour × intensity must be finite, not negative and at most {}", Number(MAX_INTENSITY))]
    LightColor,
    #[error("range {} must lie in [{}, {}]", Number(*.0), Number(*LENGTHS.start()), Number(*LENGTHS.end()))]
    Range(f32),
    #[error("its node's position is not finite or lies beyond ±{}", Number(MAX_COORDINATE))]
    LightPosition,
    #[error("yfov {} rad, znear {}, zfar {}: need 0 < yfov < π and 0 < znear < zfar, both in [{}, {}]", Number(*yfov), Number(*znear), Number(*zfar), Number(*LENGTHS.start()), Number(*LENGTHS.end()))]
    Perspective { yfov: f32, znear: f32, zfar: f32 },
    #[error("ymag {}, znear {}, zfar {}: need ymag > 0 and 0 ≤ znear < zfar, ymag and zfar in [{}, {}]", Number(*ymag), Number(*znear), Number(*zfar), Number(*LENGTHS.start()), Number(*LENGTHS.end()))]
    Orthographic { ymag: f32, znear: f32, zfar: f32 },
    #[error("its node's transform is not usable (not finite, beyond ±{}, or it collapses the view direction)", Number(MAX_COORDINATE))]
    CameraTransform,
}

impl GltfError {
    /// This problem, said to be in `part`.
    fn within(self, part: Part) -> GltfError {
        GltfError::In { part, problem: Box::new(self) }
    }

    /// Where a texture's image is missing or of a format manylights does not read (what a
    /// viewer shows with a stand-in and a warning), why, in words; None for anything else —
    /// a file not let read, bytes of no image format, malformed data —, which refuses the
    /// model.
    fn left_out_because(&self) -> Option<String> {
        match self {
            GltfError::In { problem, .. } => problem.left_out_because(),
            GltfError::External { reference, problem: ReferenceError::Read(ReadError::Io(e)) }
                if e.kind() == std::io::ErrorKind::NotFound =>
            {
                Some(format!("its file '{reference}' does not exist"))
            }
            GltfError::ImageContainer(_) => Some(self.to_string()),
            // A format the decoder knows but was not built to read (bytes of no format are
            // malformed, and refused).
            GltfError::Decode(image::ImageError::Unsupported(e)) if e.format_hint() != image::error::ImageFormatHint::Unknown => {
                Some(format!("its format is not one manylights reads ({self})"))
            }
            _ => None,
        }
    }
}

/// What the file animates or deforms, which manylights draws still: skins (the meshes in
/// their bind pose), animations, morph targets (the base shape), one warning each.
fn motion_left_out(doc: &gltf::Document) -> Vec<String> {
    let mut left = Vec::new();
    let skins = doc.skins().count();
    if skins > 0 {
        left.push(format!("{skins} skin(s) are not applied: skinned meshes are drawn in their bind pose"));
    }
    let animations = doc.animations().count();
    if animations > 0 {
        left.push(format!("{animations} animation(s) are not played: the scene is drawn as the file places it"));
    }
    let morphed = doc.meshes().filter(|m| m.primitives().any(|p| p.morph_targets().next().is_some())).count();
    if morphed > 0 {
        left.push(format!("the morph targets of {morphed} mesh(es) are not applied: they are drawn in their base shape"));
    }
    left
}

/// The containers of GPU texture formats, by their first bytes: read by no decoder here.
fn image_container(bytes: &[u8]) -> Option<&'static str> {
    const KINDS: [(&[u8], &str); 4] =
        [(b"\xABKTX 20\xBB", "KTX2"), (b"\xABKTX 11\xBB", "KTX"), (b"DDS ", "DDS"), (b"sB", "Basis Universal")];
    KINDS.iter().find(|(magic, _)| bytes.starts_with(magic)).map(|&(_, name)| name)
}

/// The first three validation errors, and how many more there are.
fn describe_invalid(errors: &[(gltf::json::Path, gltf::json::validation::Error)]) -> String {
    let first: Vec<String> = errors.iter().take(3).map(|(path, err)| format!("{path}: {err}")).collect();
    let more = if errors.len() > 3 { format!(" (and {} more)", errors.len() - 3) } else { String::new() };
    first.join("; ") + &more
}

/// Load the glTF or GLB file at `path` (external buffers relative to its folder), its
/// materials as material variant `variant` has them where it names one.
pub fn load(path: &Path, variant: Option<&str>) -> Result<SceneFile, GltfFileError> {
    let fail = |problem: GltfError| GltfFileError { path: path.to_path_buf(), problem };
    let bytes = read_regular(path, MAX_FILE_BYTES).map_err(|e| fail(e.into()))?;
    let (scene, warnings) = from_bytes_as(&bytes, path.parent(), variant).map_err(fail)?;
    Ok(SceneFile { scene, shading: Some("pbr".into()), warnings })
}

/// Read a glTF scene from the file's bytes, and what it holds that is left out; `base` is the
/// folder external buffers are in (None: external buffers are refused).
pub fn from_bytes(bytes: &[u8], base: Option<&Path>) -> Result<(Scene, Vec<String>), GltfError> {
    from_bytes_as(bytes, base, None)
}

/// `from_bytes` with the materials of material variant `variant` where it names one.
pub fn from_bytes_as(bytes: &[u8], base: Option<&Path>, variant: Option<&str>) -> Result<(Scene, Vec<String>), GltfError> {
    if bytes.is_empty() {
        return Err(GltfError::Empty);
    }
    let gltf = parse_and_validate(bytes)?;
    // Optional extensions we do not read are left out, and said so.
    let unread: Vec<String> = gltf.extensions_used().filter(|e| !supported(e)).map(str::to_owned).collect();
    let variant = variant.map(|name| material_variants::variant_index(&gltf.document, name)).transpose()?;
    let buffers = load_buffers(&gltf, base)?;
    let mut builder = Builder {
        variant,
        doc: &gltf.document,
        base,
        textures: Vec::new(),
        texture_bytes: 0,
        directional: Vec::new(),
        cones: Vec::new(),
        by_texture: HashMap::new(),
        buffers,
        meshes: Vec::new(),
        by_primitive: HashMap::new(),
        objects: Vec::new(),
        lights: Vec::new(),
        camera: None,
        vertices: 0,
        warnings: unread.into_iter().map(|e| format!("extension {e} is not supported; the file is read without it")).collect(),
        mixed_transforms: Default::default(),
    };
    builder.warnings.extend(motion_left_out(&gltf.document));
    let parents = node_parents(&gltf.document)?;
    let roots: Vec<gltf::Node> = match gltf.default_scene().or_else(|| gltf.scenes().next()) {
        Some(scene) => {
            check_roots(&scene, &parents)?;
            scene.nodes().collect()
        }
        // No scene: every node nobody names as a child.
        None => gltf.nodes().filter(|n| parents[n.index()].is_none()).collect(),
    };
    // Depth first in document order (objects and lights keep the file's order).
    let mut stack: Vec<(gltf::Node, Mat4, usize)> = roots.into_iter().rev().map(|n| (n, Mat4::IDENTITY, 0)).collect();
    while let Some((node, parent, depth)) = stack.pop() {
        if depth > MAX_NODE_DEPTH {
            return Err(GltfError::TooDeep(node.index()));
        }
        check_node_fields(node.index(), &gltf.document.as_json().nodes[node.index()])?;
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(GltfError::NodeTransform(node.index()));
        }
        let world = parent * local;
        check_node_transform(node.index(), &world)?;
        if local.row(3) != Vec4::W {
            return Err(GltfError::NodeProjective(node.index()));
        }
        builder.node(&node, world)?;
        let children: Vec<gltf::Node> = node.children().collect();
        stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
    }
    if builder.objects.is_empty() {
        return Err(GltfError::NoTriangles);
    }
    let Builder { objects, lights, camera, meshes, mut warnings, textures, directional, mut cones, mixed_transforms, .. } = builder;
    if !mixed_transforms.is_empty() {
        let names: Vec<String> = mixed_transforms.into_iter().collect();
        warnings.push(format!(
            "material{} {}: textures with different texture transforms (KHR_texture_transform); the base colour's is used for all",
            if names.len() == 1 { "" } else { "s" },
            names.join(", ")
        ));
    }
    if cones.iter().all(|c| *c == LightCone::NONE) {
        cones.clear();
    }
    let mut scene = Scene { meshes, textures, directional, cones, ..Scene::new(objects, lights, Camera::seed()) };
    // The framing camera and the lights fitted to the scene are made from its box.
    check_extent(&scene)?;
    check_draw_work(&scene)?;
    scene.camera = match camera {
        Some(c) => c,
        None => {
            scene.camera_framed = true;
            framing_camera(&scene)
        }
    };
    Ok((scene, warnings))
}

/// The gltf crate's parse and validation, minus its one known panic: its validation indexes
/// the accessor a primitive's POSITION names without checking it exists (gltf-json 1.4.1,
/// mesh.rs), so that index is checked first; and the required extensions, checked here.
fn parse_and_validate(bytes: &[u8]) -> Result<gltf::Gltf, GltfError> {
    check_glb_header(bytes)?;
    let raw = gltf::Gltf::from_slice_without_validation(bytes).map_err(describe_gltf_error)?;
    let blob = raw.blob;
    let mut root = raw.document.into_json();
    check_version(&root.asset)?;
    // Required extensions are checked here, against what we read: the crate's validation knows
    // only the extensions it parses itself (not clearcoat or sheen, which we read raw).
    if let Some(ext) = root.extensions_required.iter().find(|e| !supported(e)) {
        return Err(GltfError::RequiredExtension(ext.clone()));
    }
    root.extensions_required.clear();
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, primitive) in mesh.primitives.iter().enumerate() {
            for (semantic, index) in &primitive.attributes {
                if index.value() >= root.accessors.len() {
                    let name = match semantic {
                        gltf::json::validation::Checked::Valid(s) => s.to_string(),
                        gltf::json::validation::Checked::Invalid => "an attribute".into(),
                    };
                    let problem = GltfError::NoAccessor { attribute: name, accessor: index.value(), accessors: root.accessors.len() };
                    return Err(problem.within(Part::Primitive { mesh: m, primitive: p }));
                }
            }
        }
    }
    let document = gltf::Document::from_json(root).map_err(describe_gltf_error)?;
    Ok(gltf::Gltf { document, blob })
}

/// How far from 1 a node's rotation quaternion may be: exporters' rounding (a few 1e-7),
/// never a zero or scaled quaternion, which would scale or flatten the node.
const ROTATION_LENGTH_TOLERANCE: f32 = 1e-3;

/// glTF's rules for a node's transform fields: a matrix or translation-rotation-scale, not
/// both; a rotation of unit length.
fn check_node_fields(index: usize, node: &gltf::json::Node) -> Result<(), GltfError> {
    if node.matrix.is_some() && (node.translation.is_some() || node.rotation.is_some() || node.scale.is_some()) {
        return Err(GltfError::NodeMatrixAndTrs(index));
    }
    if let Some(q) = &node.rotation {
        let length = q.0.iter().map(|c| c * c).sum::<f32>().sqrt();
        if !length.is_finite() || (length - 1.0).abs() > ROTATION_LENGTH_TOLERANCE {
            return Err(GltfError::NodeRotation { node: index, length });
        }
    }
    Ok(())
}

/// A GLB's 12-byte header, checked before the gltf crate reads it: its length field less the
/// header is computed unchecked there (gltf 1.4.1, binary.rs — an overflow found by the fuzzer).
/// The length must be the file's: glTF says it is, and a file longer than it says holds bytes
/// nothing reads.
fn check_glb_header(bytes: &[u8]) -> Result<(), GltfError> {
    if !bytes.starts_with(b"glTF") {
        return Ok(());
    }
    let word = |at: usize| bytes.get(at..at + 4).map(|b| u32::from_le_bytes(b.try_into().expect("four bytes")));
    let (Some(version), Some(length)) = (word(4), word(8)) else {
        return Err(GltfError::Glb(GlbHeader::CutShort));
    };
    if version != 2 {
        return Err(GltfError::Glb(GlbHeader::Version(version)));
    }
    if (length as usize) < 12 + 8 || length as usize != bytes.len() {
        return Err(GltfError::Glb(GlbHeader::Length { claimed: length, actual: bytes.len() }));
    }
    // The chunks: JSON first, then (glTF) the binary chunk and any others, each whole, and
    // nothing after the last.
    let mut at = 12;
    let mut chunk = 0;
    while at < bytes.len() {
        let (Some(claimed), Some(kind)) = (word(at), word(at + 4)) else {
            return Err(GltfError::Glb(GlbHeader::Trailing(bytes.len() - at)));
        };
        let left = bytes.len() - at - 8;
        if claimed as usize > left {
            return Err(GltfError::Glb(GlbHeader::ChunkLength { chunk, kind, claimed, left }));
        }
        if chunk == 0 && kind != u32::from_le_bytes(*b"JSON") {
            return Err(GltfError::Glb(GlbHeader::FirstNotJson(kind)));
        }
        at += 8 + claimed as usize;
        chunk += 1;
    }
    Ok(())
}

/// glTF 2.x (its version "major.minor"; a later minor version reads as 2.0, what it adds
/// unread), and no minVersion above 2.0: a file that needs more than glTF 2.0 is refused.
fn check_version(asset: &gltf::json::Asset) -> Result<(), GltfError> {
    let parse = |v: &str| -> Option<(u64, u64)> {
        let (major, minor) = v.split_once('.')?;
        let number = |d: &str| d.bytes().all(|b| b.is_ascii_digit()).then(|| d.parse().ok()).flatten();
        Some((number(major)?, number(minor)?))
    };
    if !matches!(parse(&asset.version), Some((2, _))) {
        return Err(GltfError::Version(asset.version.clone()));
    }
    match &asset.min_version {
        Some(min) if parse(min) != Some((2, 0)) => Err(GltfError::MinVersion(min.clone())),
        _ => Ok(()),
    }
}

/// Each node's parent. glTF's nodes form disjoint trees: a node named as a child twice (by
/// two nodes, or twice by one) is refused — followed from each parent, a chain of such nodes
/// would be drawn 2ⁿ times — and so is a cycle (nodes no root leads to), named by a node in it.
fn node_parents(doc: &gltf::Document) -> Result<Vec<Option<usize>>, GltfError> {
    let mut parents: Vec<Option<usize>> = vec![None; doc.nodes().len()];
    for node in doc.nodes() {
        for child in node.children() {
            let slot = &mut parents[child.index()];
            if let Some(first) = *slot {
                return Err(GltfError::TwoParents { node: child.index(), first, second: node.index() });
            }
            *slot = Some(node.index());
        }
    }
    // Every node a root leads to; with one parent each, the others hang from a cycle.
    let mut reached = vec![false; parents.len()];
    let mut stack: Vec<gltf::Node> = doc.nodes().filter(|n| parents[n.index()].is_none()).collect();
    while let Some(node) = stack.pop() {
        reached[node.index()] = true;
        stack.extend(node.children());
    }
    if let Some(mut node) = reached.iter().position(|r| !r) {
        // Up as many parents as there are nodes: inside the cycle.
        for _ in 0..parents.len() {
            node = parents[node].unwrap_or(node);
        }
        return Err(GltfError::Cycle(node));
    }
    Ok(parents)
}

/// A scene's roots: each a root (no parent), each named once.
fn check_roots(scene: &gltf::Scene, parents: &[Option<usize>]) -> Result<(), GltfError> {
    let mut seen = std::collections::HashSet::new();
    for node in scene.nodes().map(|n| n.index()) {
        if let Some(parent) = parents[node] {
            return Err(GltfError::RootWithParent { scene: scene.index(), node, parent });
        }
        if !seen.insert(node) {
            return Err(GltfError::RootTwice { scene: scene.index(), node });
        }
    }
    Ok(())
}

/// How much of a cube's volume a transform's axes may lose to shear before it counts as
/// flattening it: |det| over the product of the axes' lengths (1 at right angles).
const LEAST_AXES_VOLUME: f64 = 1e-6;

/// A node's transform in the world: every axis scaled within SCALES, and not flat (a singular
/// matrix, an all-zero one among them, has no normal matrix and draws nothing).
fn check_node_transform(node: usize, world: &Mat4) -> Result<(), GltfError> {
    // In f64: the squares of an f32 axis of 1e38 would overflow.
    let m = Mat3::from_mat4(*world).as_dmat3();
    let scales = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
    let volume = m.determinant().abs();
    if volume == 0.0 || scales.contains(&0.0) {
        return Err(GltfError::NodeSingular(node));
    }
    if let Some(scale) = scales.into_iter().find(|&s| !SCALES.contains(&(s as f32))) {
        return Err(GltfError::NodeScale { node, scale: scale as f32 });
    }
    if volume < LEAST_AXES_VOLUME * scales.iter().product::<f64>() {
        return Err(GltfError::NodeSingular(node));
    }
    Ok(())
}

/// The gltf crate's error: its validation errors (which name the JSON path), or what it could
/// not read.
fn describe_gltf_error(e: gltf::Error) -> GltfError {
    match e {
        gltf::Error::Validation(errors) => GltfError::Invalid(errors),
        other => GltfError::Unreadable(other),
    }
}

/// Every buffer's bytes, each as long as the file says it is, give or take the up to 3 bytes
/// of padding that end a GLB's binary chunk (its length is a multiple of 4).
fn load_buffers(gltf: &gltf::Gltf, base: Option<&Path>) -> Result<Vec<Vec<u8>>, GltfError> {
    let mut out = Vec::new();
    let mut total = 0u64;
    for buffer in gltf.buffers() {
        let length = buffer.length() as u64;
        let what = Part::Buffer(buffer.index());
        total += length;
        if length > MAX_FILE_BYTES || total > MAX_FILE_BYTES {
            return Err(GltfError::BufferTooLarge { claimed: length }.within(what));
        }
        let most = length + BUFFER_PADDING;
        let data = match buffer.source() {
            // glTF: only the first buffer may be the binary chunk (each other one would be
            // another copy of it).
            gltf::buffer::Source::Bin if buffer.index() > 0 => return Err(GltfError::BinaryChunkNotFirst.within(what)),
            gltf::buffer::Source::Bin => gltf.blob.as_ref().ok_or_else(|| GltfError::NoBinaryChunk.within(what))?.clone(),
            gltf::buffer::Source::Uri(uri) => read_uri(uri, base, most).map_err(|e| {
                // A file longer than its buffer: said as the mismatch it is.
                match e {
                    GltfError::External { problem: ReferenceError::Read(ReadError::TooLarge { bytes, .. }), .. } => {
                        GltfError::BufferLong { holds: bytes, claims: length }
                    }
                    other => other,
                }
                .within(what)
            })?,
        };
        let holds = data.len() as u64;
        if holds < length {
            return Err(GltfError::BufferShort { holds: data.len(), claims: length }.within(what));
        }
        if holds > most {
            return Err(GltfError::BufferLong { holds, claims: length }.within(what));
        }
        out.push(data);
    }
    Ok(out)
}

/// A buffer's or an image's data, at most `max` bytes: a base64 data URI, or a file the
/// (percent-encoded) URI names relative to the glTF's folder, inside it (`read_reference`).
/// URIs with a scheme name files elsewhere, or on the network.
fn read_uri(uri: &str, base: Option<&Path>, max: u64) -> Result<Vec<u8>, GltfError> {
    // A scheme is case-insensitive (RFC 3986): DATA: is a data URI too.
    if let Some(rest) = uri.get(..5).filter(|scheme| scheme.eq_ignore_ascii_case("data:")).map(|_| &uri[5..]) {
        let (_, data) = rest.split_once(";base64,").ok_or(GltfError::NotBase64)?;
        return base64::engine::general_purpose::STANDARD.decode(data).map_err(GltfError::Base64);
    }
    if has_scheme(uri) {
        return Err(GltfError::Remote(uri.to_owned()));
    }
    let path = percent_decoded(uri).ok_or_else(|| GltfError::BadUri(uri.to_owned()))?;
    let base = base.ok_or(GltfError::NoFolder)?;
    read_reference(base, Path::new(&path), max).map_err(|problem| GltfError::External { reference: uri.to_owned(), problem })
}

/// Whether `uri` starts with a scheme (RFC 3986: a letter, then letters, digits, `+`, `-`
/// or `.`, then `:` before any `/`, `?` or `#`), as `file:` and `https:` do.
fn has_scheme(uri: &str) -> bool {
    let Some(end) = uri.find([':', '/', '?', '#']).filter(|&i| uri[i..].starts_with(':')) else { return false };
    let scheme = &uri[..end];
    scheme.starts_with(|c: char| c.is_ascii_alphabetic()) && scheme.chars().all(|c| c.is_ascii_alphanumeric() || "+-.".contains(c))
}

/// `uri` with every `%XX` replaced by the byte it encodes; None where a `%` is not followed by
/// two hexadecimal digits or the bytes are not UTF-8.
fn percent_decoded(uri: &str) -> Option<String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3).filter(|h| h.iter().all(u8::is_ascii_hexdigit))?;
            out.push(u8::from_str_radix(std::str::from_utf8(hex).ok()?, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    String::from_utf8(out).ok()
}

/// One of a primitive's meshes: its index in `Builder::meshes`, the centre and half-size of
/// the box it was fitted from, and whether it holds twin faces.
#[derive(Clone, Copy, Debug)]
struct LoadedMesh {
    mesh: u32,
    centre: Vec3,
    half: f32,
    twin_faces: bool,
}

/// Fit `mesh` into [−1, 1]³ (what every mesh of a scene does; the object's transform undoes
/// it): returns its box's centre and half-size.
fn fit_unit_box(mesh: &mut Mesh) -> (Vec3, f32) {
    let (lo, hi) = crate::mesh::bounds(mesh);
    let centre = (lo + hi) * 0.5;
    let half = ((hi - lo).max_element() * 0.5).max(f32::MIN_POSITIVE);
    for v in &mut mesh.vertices {
        v.position = ((Vec3::from(v.position) - centre) / half).to_array();
    }
    (centre, half)
}

struct Builder<'a> {
    doc: &'a gltf::Document,
    /// Where external files are (None: refused).
    base: Option<&'a Path>,
    textures: Vec<TextureImage>,
    directional: Vec<DirectionalLight>,
    /// One per light in `lights` (kept only if one of them is a spot).
    cones: Vec<LightCone>,
    /// Bytes the decoded textures take (with their mip chains): at most MAX_TEXTURE_BYTES.
    texture_bytes: u64,
    /// (image, how its texels are read, sampler) → index in `textures`: each image decoded
    /// once per reading.
    by_texture: HashMap<(usize, Texels, TextureSampler), u32>,
    buffers: Vec<Vec<u8>>,
    meshes: Vec<Mesh>,
    /// (mesh, primitive) → its meshes, so that instanced meshes are loaded once.
    by_primitive: HashMap<(usize, usize), Vec<LoadedMesh>>,
    objects: Vec<Object>,
    lights: Vec<PointLight>,
    camera: Option<Camera>,
    vertices: usize,
    /// What the file holds that is left out.
    warnings: Vec<String>,
    /// The materials whose textures carry different texture transforms, by name.
    mixed_transforms: std::collections::BTreeSet<String>,
    /// Extension textures left out, by material name.
    /// The material variant drawn (KHR_materials_variants), if one was asked for.
    variant: Option<usize>,
}

impl Builder<'_> {
    fn node(&mut self, node: &gltf::Node, world: Mat4) -> Result<(), GltfError> {
        if let Some(mesh) = node.mesh() {
            for primitive in mesh.primitives() {
                let what = Part::Primitive { mesh: mesh.index(), primitive: primitive.index() };
                let m = material_variants::material_of(self.doc, &primitive, self.variant).map_err(|e| e.within(what))?;
                let Some(parts) = self.primitive(&mesh, &primitive, m.double_sided()).map_err(|e| e.within(what))? else {
                    continue;
                };
                let (material, mut extras, mixed, lobe_textures) = material(&m, self.doc.textures().len()).map_err(|e| e.within(what))?;
                // The volume's thickness from the mesh's units to the world's: the node's mean
                // scale (the cube root of its volume's scale).
                extras.lobes.thickness *= glam::Mat3::from_mat4(world).determinant().abs().cbrt();
                let named = || match m.name() {
                    Some(name) => format!("{} '{name}'", MaterialName(m.index())),
                    None => MaterialName(m.index()).to_string(),
                };
                if mixed {
                    self.mixed_transforms.insert(named());
                }
                let textures = self.object_textures(&m, &lobe_textures).map_err(|e| e.within(what))?;
                for part in parts {
                    if self.objects.len() == MAX_OBJECTS {
                        return Err(GltfError::TooManyPrimitives);
                    }
                    // The mesh was stored fitted to [−1, 1]³: undo that inside the object's transform.
                    let transform = world * Mat4::from_translation(part.centre) * Mat4::from_scale(Vec3::splat(part.half));
                    // Twin faces are drawn single-sided: each face from its own side (twin_faces).
                    let extras = MaterialExtras { double_sided: extras.double_sided && !part.twin_faces, ..extras };
                    self.objects.push(Object { mesh: MeshKind::Loaded(part.mesh), transform, material, textures, extras });
                }
            }
        }
        if let Some(light) = node.light() {
            self.light(&light, world).map_err(|e| e.within(Part::Light(light.index())))?;
        }
        if let (Some(camera), None) = (node.camera(), &self.camera) {
            self.camera = camera_at(&camera, world, &mut self.warnings).map_err(|e| e.within(Part::Camera(camera.index())))?;
        }
        Ok(())
    }

    /// Load a primitive's triangles (once per primitive): one mesh, or where its material (the
    /// one drawn: `double_sided` is that material's) is double-sided and it has twin faces, two
    /// (the twins apart); None for points and lines.
    fn primitive(
        &mut self,
        mesh: &gltf::Mesh,
        primitive: &gltf::Primitive,
        double_sided: bool,
    ) -> Result<Option<Vec<LoadedMesh>>, GltfError> {
        use gltf::mesh::Mode;
        let key = (mesh.index(), primitive.index());
        if let Some(known) = self.by_primitive.get(&key) {
            return Ok(Some(known.clone()));
        }
        let mode = primitive.mode();
        if !matches!(mode, Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan) {
            self.warnings.push(format!("mesh {} primitive {}: {mode:?} are not drawn (triangles only)", key.0, key.1));
            return Ok(None);
        }
        let position = primitive.get(&gltf::Semantic::Positions).ok_or(GltfError::NoPositions)?;
        // KHR_mesh_quantization: integer attributes, normalised or not.
        let quantized = self.doc.extensions_used().any(|e| e == "KHR_mesh_quantization");
        let positions = read_floats::<3>(&self.buffers, &position, "POSITION", quantized)?;
        let far =
            positions.iter().enumerate().find_map(|(index, p)| p.iter().find(|x| x.abs() > MAX_COORDINATE).map(|&value| (index, value)));
        if let Some((index, value)) = far {
            return Err(GltfError::TooFar { index, value }.within(Part::Data("POSITION")));
        }
        let count = positions.len();
        self.vertices += count;
        if self.vertices > MAX_VERTICES {
            return Err(GltfError::TooManyVertices);
        }
        let normals = match primitive.get(&gltf::Semantic::Normals) {
            Some(a) => Some(read_floats::<3>(&self.buffers, &a, "NORMAL", quantized)?),
            None => None,
        };
        let uvs = match primitive.get(&gltf::Semantic::TexCoords(0)) {
            Some(a) => Some(read_floats::<2>(&self.buffers, &a, "TEXCOORD_0", quantized)?),
            None => None,
        };
        for (attribute, n) in [("NORMAL", normals.as_ref().map(Vec::len)), ("TEXCOORD_0", uvs.as_ref().map(Vec::len))] {
            if let Some(entries) = n.filter(|&n| n != count) {
                return Err(GltfError::AttributeCount { attribute, entries, positions: count });
            }
        }
        let indices = match primitive.indices() {
            Some(a) => read_indices(&self.buffers, &a, count)?,
            None => (0..count as u32).collect(),
        };
        let triangles = triangle_list(mode, &indices)?;
        if triangles.is_empty() {
            return Ok(None);
        }
        let mut out = Mesh::default();
        let vertex = |i: u32, n: Vec3| {
            let i = i as usize;
            Vertex { position: positions[i], normal: n.to_array(), uv: uvs.as_ref().map_or([0.0; 2], |u| u[i]), tangent: [0.0; 4] }
        };
        match &normals {
            Some(ns) => {
                out.vertices = (0..count as u32).map(|i| vertex(i, Vec3::from(ns[i as usize]).normalize_or(Vec3::Y))).collect();
                out.indices = triangles;
            }
            None => {
                // glTF: without normals, flat shading — each triangle its own three vertices.
                self.vertices += triangles.len();
                if self.vertices > MAX_VERTICES {
                    return Err(GltfError::TooManyVertices);
                }
                for tri in triangles.chunks_exact(3) {
                    let p = |k: usize| Vec3::from(positions[tri[k] as usize]);
                    let n = (p(1) - p(0)).cross(p(2) - p(0)).normalize_or(Vec3::Y);
                    for &i in tri {
                        out.indices.push(out.vertices.len() as u32);
                        out.vertices.push(vertex(i, n));
                    }
                }
            }
        }
        compute_tangents(&mut out);
        let pieces = match double_sided.then(|| twin_faces::split_twin_faces(&out)).flatten() {
            Some((rest, twins)) => vec![(rest, false), (twins, true)],
            None => vec![(out, false)],
        };
        let mut parts = Vec::new();
        for (mut piece, twin_faces) in pieces.into_iter().filter(|(m, _)| !m.indices.is_empty()) {
            let (centre, half) = fit_unit_box(&mut piece);
            parts.push(LoadedMesh { mesh: self.meshes.len() as u32, centre, half, twin_faces });
            self.meshes.push(piece);
        }
        self.by_primitive.insert(key, parts.clone());
        Ok(Some(parts))
    }

    /// The material's textures (first texture coordinates) with their samplers, its
    /// extensions' (`lobes`) among them.
    fn object_textures(&mut self, m: &gltf::Material, lobes: &LobeTextureRefs) -> Result<ObjectTextures, GltfError> {
        let name = MaterialName(m.index());
        let pbr = m.pbr_metallic_roughness();
        let base_color = pbr.base_color_texture().map(|t| (t.texture(), t.tex_coord()));
        let metallic_roughness = pbr.metallic_roughness_texture().map(|t| (t.texture(), t.tex_coord()));
        let normal = m.normal_texture().map(|t| (t.texture(), t.tex_coord()));
        let occlusion = m.occlusion_texture().map(|t| (t.texture(), t.tex_coord()));
        let emissive = m.emissive_texture().map(|t| (t.texture(), t.tex_coord()));
        let doc = self.doc;
        let mut slot = |what: &'static str, texture: Option<(gltf::Texture, u32)>, texels: Texels| -> Result<Option<u32>, GltfError> {
            let Some((texture, set)) = texture else { return Ok(None) };
            if set != 0 {
                self.warnings.push(format!("material {name}: the {what} texture names TEXCOORD_{set}; TEXCOORD_0 is used"));
            }
            match self.texture(&texture, texels) {
                Ok(slot) => Ok(Some(slot)),
                // Missing or unreadable: drawn without it (its factor alone), as a viewer does.
                Err(e) => match e.left_out_because() {
                    Some(why) => {
                        let image = texture.source().index();
                        self.warnings.push(format!("material {name}: the {what} texture (image {image}) is left out: {why}"));
                        Ok(None)
                    }
                    None => Err(e.within(Part::Texture { material: name.0, slot: what })),
                },
            }
        };
        let mut slots = [None; TEXTURE_SLOTS];
        slots[..FIRST_LOBE_SLOT].copy_from_slice(&[
            slot("base colour", base_color, Texels::Colour)?,
            slot("normal", normal, Texels::UnitNormals)?,
            slot("metallic-roughness", metallic_roughness, Texels::Data)?,
            slot("occlusion", occlusion, Texels::Data)?,
            slot("emissive", emissive, Texels::Colour)?,
        ]);
        // The extensions' textures (their indices checked against the file's textures).
        for (i, (r, (_, what, texels))) in lobes.iter().zip(LOBE_TEXTURE_FIELDS).enumerate() {
            let texture = r.and_then(|r| doc.textures().nth(r.index).map(|t| (t, r.tex_coord)));
            slots[FIRST_LOBE_SLOT + i] = slot(what, texture, texels)?;
        }
        Ok(ObjectTextures::from_slots(slots))
    }

    /// A glTF texture: its image decoded to RGBA8 (once per way its texels are read) with its
    /// sampler.
    fn texture(&mut self, texture: &gltf::Texture, texels: Texels) -> Result<u32, GltfError> {
        let sampler = sampler_of(&texture.sampler());
        let index = texture.source().index();
        if let Some(&known) = self.by_texture.get(&(index, texels, sampler)) {
            return Ok(known);
        }
        let decoded = match self.by_texture.iter().find(|((i, t, _), _)| (*i, *t) == (index, texels)) {
            // The same image with another sampler: decoded already, its texels shared.
            Some((_, &other)) => TextureImage { sampler, ..self.textures[other as usize].clone() },
            None => {
                let image = self.image(index, texels == Texels::Colour).map_err(|e| e.within(Part::Image(index)))?;
                let image = if texels == Texels::UnitNormals { unit_normals(image) } else { image };
                TextureImage { sampler, ..image }
            }
        };
        let slot = self.textures.len() as u32;
        self.textures.push(decoded);
        self.by_texture.insert((index, texels, sampler), slot);
        Ok(slot)
    }

    /// Image `index` decoded to RGBA8, checked before it is read: the gltf crate's own accessor
    /// for an image's source panics on an image with neither a URI nor a buffer view, and on a
    /// buffer view without a MIME type.
    fn image(&mut self, index: usize, srgb: bool) -> Result<TextureImage, GltfError> {
        let json = &self.doc.as_json().images[index];
        let bytes: Vec<u8> = match (&json.uri, &json.buffer_view, &json.mime_type) {
            (Some(uri), None, _) => read_uri(uri, self.base, MAX_IMAGE_BYTES)?,
            (None, Some(view), Some(_)) => {
                let view = self.doc.views().nth(view.value()).ok_or(GltfError::NoImageView)?;
                view_bytes(&self.buffers, &view, "its data")?.to_vec()
            }
            (None, Some(_), None) => return Err(GltfError::NoMimeType),
            _ => return Err(GltfError::NoImageSource),
        };
        // (A file is capped as it is read; a data URI or a buffer view only here.)
        if bytes.len() as u64 > MAX_IMAGE_BYTES {
            return Err(GltfError::ImageTooLarge(bytes.len()));
        }
        if let Some(container) = image_container(&bytes) {
            return Err(GltfError::ImageContainer(container));
        }
        self.texture_bytes = within_texture_budget(&bytes, self.texture_bytes)?;
        decode_image(&bytes, srgb)
    }

    fn light(&mut self, light: &gltf::khr_lights_punctual::Light, world: Mat4) -> Result<(), GltfError> {
        use gltf::khr_lights_punctual::Kind;
        let (kind, cone) = match light.kind() {
            Kind::Point => ("point", None),
            Kind::Spot { inner_cone_angle, outer_cone_angle } => ("spot", Some((inner_cone_angle, outer_cone_angle))),
            Kind::Directional => ("directional", None),
        };
        if kind == "directional" {
            // The node's −Z, in lux: colour × intensity.
            let direction = world.transform_vector3(-Vec3::Z).normalize_or_zero();
            let color = Vec3::from(light.color()) * light.intensity();
            if direction == Vec3::ZERO || !direction.is_finite() || !light_color(color) {
                return Err(GltfError::Directional);
            }
            if self.directional.len() == MAX_DIRECTIONAL_LIGHTS {
                return Err(GltfError::TooManyDirectional);
            }
            self.directional.push(DirectionalLight { direction, color });
            return Ok(());
        }
        let cone = match cone {
            None => LightCone::NONE,
            Some((inner, outer)) => {
                // glTF: 0 ≤ inner < outer ≤ π/2.
                if !(inner >= 0.0 && inner < outer && outer <= std::f32::consts::FRAC_PI_2 + 1e-6) {
                    return Err(GltfError::SpotCone { inner, outer });
                }
                let axis = world.transform_vector3(-Vec3::Z).normalize_or_zero();
                if axis == Vec3::ZERO || !axis.is_finite() {
                    return Err(GltfError::SpotDirection);
                }
                LightCone::spot(axis, inner, outer)
            }
        };
        let color = Vec3::from(light.color()) * light.intensity();
        if !light_color(color) {
            return Err(GltfError::LightColor);
        }
        // Our lights end at a radius. glTF's range is one; without it, the distance where
        // intensity / d² falls to 1/256 (about what an 8-bit image still shows).
        let radius = match light.range() {
            Some(r) if LENGTHS.contains(&r) => r,
            Some(r) => return Err(GltfError::Range(r)),
            None => (light.intensity().max(0.0) * 256.0).sqrt().max(1e-3),
        };
        let position = world.transform_point3(Vec3::ZERO);
        if !within_reach(position) {
            return Err(GltfError::LightPosition);
        }
        self.lights.push(PointLight { position_radius: position.extend(radius).to_array(), color: color.extend(0.0).to_array() });
        self.cones.push(cone);
        Ok(())
    }
}

/// A light's colour × intensity: finite, not negative, at most MAX_INTENSITY.
fn light_color(color: Vec3) -> bool {
    // (glam's min and max pass over NaN: finiteness is its own test.)
    color.is_finite() && color.min_element() >= 0.0 && color.max_element() <= MAX_INTENSITY
}

/// A place within ±MAX_COORDINATE.
fn within_reach(p: Vec3) -> bool {
    p.is_finite() && p.abs().max_element() <= MAX_COORDINATE
}

/// The bytes the textures take once the image `bytes` encode is decoded (RGBA8 and its mip
/// chain, from the image's header) on top of `taken`; refused past MAX_TEXTURE_BYTES.
fn within_texture_budget(bytes: &[u8], taken: u64) -> Result<u64, GltfError> {
    let reader = image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(GltfError::ImageFormat)?;
    let (width, height) =
        crate::image_decode::guarded_decode(|| reader.into_dimensions()).ok_or(GltfError::DecoderFailed)?.map_err(GltfError::Decode)?;
    let need = u64::from(width) * u64::from(height) * 4 * 4 / 3;
    match taken.checked_add(need).filter(|&total| total <= MAX_TEXTURE_BYTES) {
        Some(total) => Ok(total),
        None => Err(GltfError::TextureBudget { width, height, need, taken }),
    }
}

/// How a texture's texels are read: colour (sRGB-encoded), data as they are, or unit normals.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Texels {
    Colour,
    Data,
    UnitNormals,
}

/// A normal map's texels made unit vectors. Many stored maps are not (lossy compression,
/// tools that write 128 for 0): a texel of length 0.98 would read, to the specular
/// anti-aliasing, as normals spread within it (a smooth visor's highlight widened as if its
/// roughness were 0.3), where only its mip levels' averages should be shorter than 1.
fn unit_normals(image: TextureImage) -> TextureImage {
    let rgba: Vec<u8> = image.rgba.chunks_exact(4).flat_map(|t| crate::textures::unit_normal_texel([t[0], t[1], t[2], t[3]])).collect();
    TextureImage { rgba: rgba.into(), ..image }
}

/// PNG or JPEG bytes as an RGBA8 texture, its size and memory capped before decoding.
fn decode_image(bytes: &[u8], srgb: bool) -> Result<TextureImage, GltfError> {
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(GltfError::ImageFormat)?;
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_TEXTURE_SIZE);
    limits.max_image_height = Some(MAX_TEXTURE_SIZE);
    limits.max_alloc = Some(1 << 30);
    reader.limits(limits);
    let decoded =
        crate::image_decode::guarded_decode(|| reader.decode()).ok_or(GltfError::DecoderFailed)?.map_err(GltfError::Decode)?.to_rgba8();
    let (width, height) = decoded.dimensions();
    Ok(TextureImage { width, height, rgba: decoded.into_raw().into(), srgb, sampler: TextureSampler::default() })
}

/// glTF's metallic-roughness factors, and its emissive factor (times
/// KHR_materials_emissive_strength), normal scale, occlusion strength, alpha mode, sides,
/// extensions and texture transform; whether its textures carry different transforms (one is
/// used: the base colour's, else the first textured slot's); the textures its extensions name
/// (in a file of `textures` textures).
fn material(m: &gltf::Material, textures: usize) -> Result<(Material, MaterialExtras, bool, LobeTextureRefs), GltfError> {
    let pbr = m.pbr_metallic_roughness();
    let [r, g, b, a] = pbr.base_color_factor();
    let (metallic, roughness) = (pbr.metallic_factor(), pbr.roughness_factor());
    let [er, eg, eb] = m.emissive_factor();
    let strength = m.occlusion_texture().map_or(1.0, |t| t.strength());
    let unit = [
        ("base colour", r),
        ("base colour", g),
        ("base colour", b),
        ("base colour alpha", a),
        ("metallic", metallic),
        ("roughness", roughness),
        ("emissive", er),
        ("emissive", eg),
        ("emissive", eb),
        ("occlusion strength", strength),
    ];
    let material = MaterialName(m.index());
    for (factor, value) in unit {
        if !(0.0..=1.0).contains(&value) {
            return Err(GltfError::Factor { material, factor, value });
        }
    }
    let normal_scale = m.normal_texture().map_or(1.0, |t| t.scale());
    if !normal_scale.is_finite() {
        return Err(GltfError::NormalScale { material, value: normal_scale });
    }
    let emissive_strength = m.emissive_strength().unwrap_or(1.0);
    if !(0.0..=MAX_INTENSITY).contains(&emissive_strength) {
        return Err(GltfError::EmissiveStrength { material, value: emissive_strength });
    }
    let alpha_mode = match m.alpha_mode() {
        gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
        gltf::material::AlphaMode::Mask => {
            let cutoff = m.alpha_cutoff().unwrap_or(0.5);
            if !(cutoff.is_finite() && cutoff >= 0.0) {
                return Err(GltfError::AlphaCutoff { material, value: cutoff });
            }
            AlphaMode::Mask { cutoff }
        }
        gltf::material::AlphaMode::Blend => AlphaMode::Blend,
    };
    let pbr = m.pbr_metallic_roughness();
    let (lobes, lobe_textures) = material_extensions::material_lobes(m, textures)?;
    let transforms: Vec<Affine2> = [pbr.base_color_texture(), pbr.metallic_roughness_texture(), m.emissive_texture()]
        .iter()
        .flatten()
        .map(texture_transform)
        .chain(lobe_textures.iter().flatten().map(|t| t.transform))
        .collect();
    let uv_transform = transforms.first().copied().unwrap_or(Affine2::IDENTITY);
    if !uv_transform.is_finite() {
        return Err(GltfError::TextureTransform { material });
    }
    let mixed = transforms.iter().any(|t| *t != uv_transform);
    let extras = MaterialExtras {
        uv_transform,
        emissive: Vec3::new(er, eg, eb) * emissive_strength,
        normal_scale,
        occlusion_strength: strength,
        alpha_mode,
        base_alpha: a,
        double_sided: m.double_sided(),
        lobes,
    };
    Ok((Material { albedo: Vec3::new(r, g, b), roughness, metallic }, extras, mixed, lobe_textures))
}

/// A texture's KHR_texture_transform as the affine map of texture coordinates it is:
/// translation · rotation · scale, the rotation's columns (cos, sin) and (−sin, cos).
fn texture_transform(info: &gltf::texture::Info) -> Affine2 {
    let Some(t) = info.texture_transform() else { return Affine2::IDENTITY };
    uv_affine(t.offset().into(), t.rotation(), t.scale().into())
}

/// KHR_texture_transform's parts as the affine map they make: translation · rotation · scale.
fn uv_affine(offset: glam::Vec2, rotation: f32, scale: glam::Vec2) -> Affine2 {
    let (sin, cos) = rotation.sin_cos();
    let columns = glam::Mat2::from_cols(glam::Vec2::new(cos, sin) * scale.x, glam::Vec2::new(-sin, cos) * scale.y);
    Affine2::from_mat2_translation(columns, offset)
}

/// A glTF sampler (filters glTF leaves open: linear, trilinear between mips).
fn sampler_of(s: &gltf::texture::Sampler) -> TextureSampler {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |w: WrappingMode| match w {
        WrappingMode::ClampToEdge => Wrap::ClampToEdge,
        WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
        WrappingMode::Repeat => Wrap::Repeat,
    };
    let mag = match s.mag_filter() {
        Some(MagFilter::Nearest) => Filter::Nearest,
        Some(MagFilter::Linear) | None => Filter::Linear,
    };
    let (min, mipmap) = match s.min_filter() {
        Some(MinFilter::Nearest) => (Filter::Nearest, None),
        Some(MinFilter::Linear) => (Filter::Linear, None),
        Some(MinFilter::NearestMipmapNearest) => (Filter::Nearest, Some(Filter::Nearest)),
        Some(MinFilter::LinearMipmapNearest) => (Filter::Linear, Some(Filter::Nearest)),
        Some(MinFilter::NearestMipmapLinear) => (Filter::Nearest, Some(Filter::Linear)),
        Some(MinFilter::LinearMipmapLinear) | None => (Filter::Linear, Some(Filter::Linear)),
    };
    TextureSampler { wrap_u: wrap(s.wrap_s()), wrap_v: wrap(s.wrap_t()), mag, min, mipmap }
}

/// The camera at a node, perspective or orthographic (its height; the width follows the
/// image, as a perspective camera's does).
fn camera_at(camera: &gltf::Camera, world: Mat4, warnings: &mut Vec<String>) -> Result<Option<Camera>, GltfError> {
    let (fov, near, far, orthographic) = match camera.projection() {
        gltf::camera::Projection::Perspective(p) => {
            let (fov, near) = (p.yfov().to_degrees(), p.znear());
            let far = p.zfar().unwrap_or(near * 1e5);
            let sane = fov > 0.0 && fov < 180.0 && LENGTHS.contains(&near) && far > near && LENGTHS.contains(&far);
            if !sane {
                return Err(GltfError::Perspective { yfov: p.yfov(), znear: near, zfar: far });
            }
            (fov, near, far, None)
        }
        gltf::camera::Projection::Orthographic(o) => {
            let (ymag, near, far) = (o.ymag(), o.znear(), o.zfar());
            let sane = LENGTHS.contains(&ymag) && near >= 0.0 && far > near && LENGTHS.contains(&far);
            if !sane {
                return Err(GltfError::Orthographic { ymag, znear: near, zfar: far });
            }
            // Depth slices are logarithmic in depth: they need a near plane in front of the eye.
            let least = far * 1e-4;
            if near < least {
                warnings.push(format!("camera {}: znear {near} is read as {least} (zfar / 10⁴)", camera.index()));
            }
            (60.0, near.max(least), far, Some(ymag))
        }
    };
    let position = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(-Vec3::Z).normalize_or_zero();
    if !within_reach(position) || forward == Vec3::ZERO {
        return Err(GltfError::CameraTransform);
    }
    if forward.y.abs() > 0.9999 {
        warnings.push(format!("camera {}: it looks straight up or down; the scene is framed instead", camera.index()));
        return Ok(None);
    }
    Ok(Some(Camera { orthographic, ..Camera::looking_at(position, position + forward, fov, near, far) }))
}

/// A camera that sees every object, from above and in front, the model filling most of a
/// default-sized image (`framing::frame_scene`; a render of another aspect frames it again for
/// its own: `SceneRequest::build`).
pub fn framing_camera(scene: &Scene) -> Camera {
    crate::framing::frame_scene(scene, crate::framing::DEFAULT_ASPECT, crate::camera::DEFAULT_FOV_Y_DEG)
}

/// Triangle-list indices from a list, strip or fan.
fn triangle_list(mode: gltf::mesh::Mode, indices: &[u32]) -> Result<Vec<u32>, GltfError> {
    use gltf::mesh::Mode;
    Ok(match mode {
        Mode::Triangles => {
            if !indices.len().is_multiple_of(3) {
                return Err(GltfError::PartialTriangle(indices.len()));
            }
            indices.to_vec()
        }
        Mode::TriangleStrip => (2..indices.len())
            .flat_map(
                |i| if i % 2 == 0 { [indices[i - 2], indices[i - 1], indices[i]] } else { [indices[i - 1], indices[i - 2], indices[i]] },
            )
            .collect(),
        _ => (2..indices.len()).flat_map(|i| [indices[0], indices[i - 1], indices[i]]).collect(),
    })
}

/// Every element of `accessor`, `size()` bytes each, back to back: read from its buffer view
/// (each range checked against view and buffer), or zeros without one, then the sparse
/// substitutions applied.
fn elements(buffers: &[Vec<u8>], accessor: &gltf::Accessor, what: &'static str) -> Result<(Vec<u8>, DataType), GltfError> {
    let element = accessor.size();
    let count = accessor.count();
    let fail = |e: GltfError| e.within(Part::Data(what));
    if count > MAX_VERTICES * 3 || count.saturating_mul(element) as u64 > MAX_FILE_BYTES {
        return Err(fail(GltfError::TooManyElements(count)));
    }
    let mut out = match accessor.view() {
        Some(view) => {
            let stride = view.stride().unwrap_or(element);
            if stride < element {
                return Err(fail(GltfError::Stride { stride, element }));
            }
            let component = accessor.data_type().size();
            if !aligned(view.offset(), accessor.offset(), component) || !stride.is_multiple_of(component) {
                let (offset, view_offset) = (accessor.offset(), view.offset());
                return Err(fail(GltfError::Misaligned { offset, view_offset, stride, component }));
            }
            let needed = match count {
                0 => Some(0),
                n => (n - 1).checked_mul(stride).and_then(|x| x.checked_add(accessor.offset())).and_then(|x| x.checked_add(element)),
            }
            .ok_or_else(|| fail(GltfError::SizeOverflow))?;
            if needed > view.length() {
                let (offset, view, length) = (accessor.offset(), view.index(), view.length());
                return Err(fail(GltfError::ViewTooShort { count, element, stride, offset, needed, view, length }));
            }
            let data = view_bytes(buffers, &view, what)?;
            (0..count).flat_map(|i| &data[accessor.offset() + i * stride..][..element]).copied().collect()
        }
        None if accessor.sparse().is_some() => {
            if count > MAX_VIEWLESS_ELEMENTS {
                return Err(fail(GltfError::TooManyZeros(count)));
            }
            vec![0; count * element]
        }
        None => return Err(fail(GltfError::NoView(accessor.index()))),
    };
    if let Some(sparse) = accessor.sparse() {
        let n = sparse.count();
        if n > count {
            return Err(fail(GltfError::TooManySparse { substitutions: n, count }));
        }
        let (indices, values) = (sparse.indices(), sparse.values());
        let index_size = match indices.index_type() {
            gltf::accessor::sparse::IndexType::U8 => 1,
            gltf::accessor::sparse::IndexType::U16 => 2,
            gltf::accessor::sparse::IndexType::U32 => 4,
        };
        let range = |data: &[u8], offset: usize, len: usize, part: &'static str| -> Result<Vec<u8>, GltfError> {
            offset
                .checked_add(len)
                .filter(|&end| end <= data.len())
                .map(|end| data[offset..end].to_vec())
                .ok_or_else(|| fail(GltfError::SparseOutside { part, len, offset }))
        };
        for (view, offset, size) in
            [(indices.view(), indices.offset(), index_size), (values.view(), values.offset(), accessor.data_type().size())]
        {
            if !aligned(view.offset(), offset, size) {
                let stride = view.stride().unwrap_or(size);
                return Err(fail(GltfError::Misaligned { offset, view_offset: view.offset(), stride, component: size }));
            }
        }
        let index_bytes = range(view_bytes(buffers, &indices.view(), what)?, indices.offset(), n * index_size, "indices")?;
        let value_bytes = range(view_bytes(buffers, &values.view(), what)?, values.offset(), n * element, "values")?;
        let mut previous = None;
        for (k, (i, value)) in index_bytes.chunks_exact(index_size).zip(value_bytes.chunks_exact(element)).enumerate() {
            let i = i.iter().rev().fold(0usize, |acc, &b| acc << 8 | b as usize);
            if i >= count || previous.is_some_and(|p| i <= p) {
                return Err(fail(GltfError::SparseIndex { k, index: i, count }));
            }
            out[i * element..][..element].copy_from_slice(value);
            previous = Some(i);
        }
    }
    Ok((out, accessor.data_type()))
}

/// Whether data `offset` bytes into a buffer view that starts `view_offset` bytes into its
/// buffer is aligned to its `component`-byte components, in the view and in the buffer (glTF).
fn aligned(view_offset: usize, offset: usize, component: usize) -> bool {
    offset.is_multiple_of(component) && view_offset.is_multiple_of(component)
}

/// The bytes of buffer view `view`, checked against its buffer.
fn view_bytes<'b>(buffers: &'b [Vec<u8>], view: &gltf::buffer::View, what: &'static str) -> Result<&'b [u8], GltfError> {
    let data = &buffers[view.buffer().index()];
    let (offset, length) = (view.offset(), view.length());
    offset
        .checked_add(length)
        .filter(|&e| e <= data.len())
        .map(|end| &data[offset..end])
        .ok_or_else(|| GltfError::ViewOutside { view: view.index(), length, offset, buffer: data.len() }.within(Part::Data(what)))
}

/// A float accessor of N components (f32, or normalised u8/u16 for texture coordinates; with
/// `quantized`, KHR_mesh_quantization's 8- and 16-bit integers too, signed or not, normalised
/// or not), every value finite.
fn read_floats<const N: usize>(
    buffers: &[Vec<u8>],
    accessor: &gltf::Accessor,
    what: &'static str,
    quantized: bool,
) -> Result<Vec<[f32; N]>, GltfError> {
    let dims = match N {
        2 => Dimensions::Vec2,
        _ => Dimensions::Vec3,
    };
    let fail = |e: GltfError| e.within(Part::Data(what));
    if accessor.dimensions() != dims {
        return Err(fail(GltfError::Dimensions { expected: dims, found: accessor.dimensions() }));
    }
    let (bytes, ty) = elements(buffers, accessor, what)?;
    let component = |bytes: &[u8], k: usize| -> Option<f32> {
        match (ty, accessor.normalized()) {
            (DataType::F32, _) => Some(f32::from_le_bytes(bytes[k * 4..k * 4 + 4].try_into().ok()?)),
            (DataType::U8, true) => Some(bytes[k] as f32 / 255.0),
            (DataType::U16, true) => Some(u16::from_le_bytes(bytes[k * 2..k * 2 + 2].try_into().ok()?) as f32 / 65535.0),
            _ if !quantized => None,
            // Signed normalised: c / max, never below −1 (glTF's rule).
            (DataType::I8, true) => Some((bytes[k] as i8 as f32 / 127.0).max(-1.0)),
            (DataType::I16, true) => Some((i16::from_le_bytes(bytes[k * 2..k * 2 + 2].try_into().ok()?) as f32 / 32767.0).max(-1.0)),
            (DataType::U8, false) => Some(bytes[k] as f32),
            (DataType::I8, false) => Some(bytes[k] as i8 as f32),
            (DataType::U16, false) => Some(u16::from_le_bytes(bytes[k * 2..k * 2 + 2].try_into().ok()?) as f32),
            (DataType::I16, false) => Some(i16::from_le_bytes(bytes[k * 2..k * 2 + 2].try_into().ok()?) as f32),
            _ => None,
        }
    };
    let mut out = Vec::with_capacity(accessor.count());
    for (i, e) in bytes.chunks_exact(accessor.size()).enumerate() {
        let mut v = [0.0; N];
        for (k, slot) in v.iter_mut().enumerate() {
            *slot = component(e, k).ok_or_else(|| fail(GltfError::ComponentType { ty, normalized: accessor.normalized() }))?;
            if !slot.is_finite() {
                return Err(fail(GltfError::NotFinite { index: i, value: *slot }));
            }
        }
        out.push(v);
    }
    Ok(out)
}

/// An index accessor (u8, u16 or u32 scalars), every index below `vertices`.
fn read_indices(buffers: &[Vec<u8>], accessor: &gltf::Accessor, vertices: usize) -> Result<Vec<u32>, GltfError> {
    let fail = |e: GltfError| e.within(Part::Data("indices"));
    if accessor.dimensions() != Dimensions::Scalar {
        return Err(fail(GltfError::NotScalar(accessor.dimensions())));
    }
    let (bytes, ty) = elements(buffers, accessor, "indices")?;
    let mut out = Vec::with_capacity(accessor.count());
    for (i, e) in bytes.chunks_exact(accessor.size()).enumerate() {
        let index = match ty {
            DataType::U8 => e[0] as u32,
            DataType::U16 => u16::from_le_bytes([e[0], e[1]]) as u32,
            DataType::U32 => u32::from_le_bytes([e[0], e[1], e[2], e[3]]),
            other => return Err(fail(GltfError::NotIndexType(other))),
        };
        if index as usize >= vertices {
            return Err(fail(GltfError::IndexOutOfRange { index: i, value: index, vertices }));
        }
        out.push(index);
    }
    Ok(out)
}

mod material_extensions;
use material_extensions::{LobeTextureRefs, LOBE_TEXTURE_FIELDS};
mod material_variants;

#[cfg(test)]
mod tests;
