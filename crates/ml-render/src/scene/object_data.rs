//! The scene's objects as the shaders read them: each object's entry in the object buffer,
//! what a draw of it pushes, and the surface variant (masked, double-sided) whose pipeline
//! draws it. The scene's GPU data and every pass that draws meshes share these.

use ml_cpu::alpha_mask::AlphaMasks;
use ml_cpu::gpu_types::{ObjectData, ObjectPush};
use ml_cpu::scene::Object;
use ml_cpu::textures::TextureImage;

/// What a mesh pipeline does with its objects' surfaces (mesh_coverage.glsl): back faces
/// culled, or drawn with the normal turned toward the viewer (double-sided); every fragment
/// kept, or alpha-tested (masked). A pipeline each, specialised, so that the opaque,
/// single-sided objects' pipeline has no test and no discard.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SurfaceVariant {
    pub double_sided: bool,
    pub masked: bool,
}

impl SurfaceVariant {
    pub const OPAQUE: SurfaceVariant = SurfaceVariant { double_sided: false, masked: false };
    pub(crate) const COUNT: usize = 4;

    /// The variant that draws object `o`.
    pub fn of(o: &Object) -> SurfaceVariant {
        SurfaceVariant { double_sided: o.extras.double_sided, masked: o.extras.masked() }
    }

    /// The variants `objects` need, the opaque one always among them.
    pub fn needed(objects: &[Object]) -> Vec<SurfaceVariant> {
        let mut out = vec![SurfaceVariant::OPAQUE];
        for v in objects.iter().map(SurfaceVariant::of) {
            if !out.contains(&v) {
                out.push(v);
            }
        }
        out
    }

    pub(crate) fn index(self) -> usize {
        usize::from(self.double_sided) * 2 + usize::from(self.masked)
    }

    /// Its specialization constants (name, value) in shading/mesh_coverage.glsl.
    pub(crate) fn spec_constants(self) -> [(&'static str, u32); 2] {
        [("MASKED_DRAW", u32::from(self.masked)), ("DOUBLE_SIDED_DRAW", u32::from(self.double_sided))]
    }
}

/// Object `o`'s entry in the object buffer (`masks`, `textures`: the scene's alpha masks and
/// textures).
pub fn object_data(o: &Object, masks: &AlphaMasks, textures: &[TextureImage]) -> ObjectData {
    let normal = glam::Mat4::from_mat3(glam::Mat3::from_mat4(o.transform).inverse().transpose());
    let [albedo_roughness, material, emissive] = material_vectors(o);
    let (alpha, alpha_texture) = masks.object_fields(o, textures);
    ObjectData {
        model: o.transform.to_cols_array_2d(),
        normal_matrix: normal.to_cols_array_2d(),
        albedo_roughness,
        material,
        emissive,
        alpha,
        alpha_texture,
        uv_transform: uv_transform_vectors(o.extras.uv_transform),
        lobes: o.extras.lobes.vectors(),
    }
}

/// What a draw of object `o` (at `index`) pushes.
pub fn object_push(o: &Object, index: u32) -> ObjectPush {
    let [albedo_roughness, material, emissive] = material_vectors(o);
    ObjectPush { ids: [index, o.textures.bits(), 0, 0], albedo_roughness, material, emissive }
}

/// The material as the shaders read it: (albedo, roughness), (metallic, occlusion strength,
/// normal scale, 0), (emissive, 0).
fn material_vectors(o: &Object) -> [[f32; 4]; 3] {
    let (m, x) = (&o.material, &o.extras);
    [m.albedo.extend(m.roughness).to_array(), [m.metallic, x.occlusion_strength, x.normal_scale, 0.0], x.emissive.extend(0.0).to_array()]
}

/// ObjectData::uv_transform of `t`.
fn uv_transform_vectors(t: glam::Affine2) -> [[f32; 4]; 2] {
    let m = t.matrix2;
    [[m.x_axis.x, m.x_axis.y, m.y_axis.x, m.y_axis.y], [t.translation.x, t.translation.y, 0.0, 0.0]]
}
