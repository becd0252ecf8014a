//! Every Rust struct shared with the shaders has the field offsets and size that SPIR-V
//! reflection of the compiled shaders reports (the std140 trap: mistake 5 of
//! docs/DESIGN.md#mistakes-we-avoid). A field moved on either side fails here.

use ml_cpu::gpu_types::{
    ClusterRange, CullCounters, CullPush, DrawIndexedCommand, EnvironmentData, FrameUniforms, GpuLayout, Instance, LargeTriangle,
    LayerObject, LightCone, LightGridDispatch, LightGridFeedback, Meshlet, ObjectData, ObjectPush, OmniRasterCounters, OmniRasterPush,
    OmniShadowPush, PointLight, RayInstance, RayNode, RayTriangle, ShadowCubeTiles, ShadowPush, StageProbePush,
};
use spirq::ty::{StructType, Type};
use spirq::ReflectConfig;
use std::collections::HashMap;

/// A struct as the shaders lay it out: member offsets and its size (the array stride where
/// it is an array element, else the end of its last member).
#[derive(Debug, PartialEq)]
struct Reflected {
    members: Vec<(String, usize)>,
    size: usize,
}

fn collect(ty: &Type, stride: Option<usize>, out: &mut HashMap<String, Reflected>) {
    match ty {
        Type::Struct(s) => {
            record(s, stride, out);
            for m in &s.members {
                collect(&m.ty, None, out);
            }
        }
        Type::Array(a) => collect(&a.element_ty, a.stride, out),
        _ => {}
    }
}

fn record(s: &StructType, stride: Option<usize>, out: &mut HashMap<String, Reflected>) {
    let Some(name) = s.name() else { return };
    let members: Vec<(String, usize)> =
        s.members.iter().map(|m| (m.name.clone().unwrap_or_default(), m.offset.expect("explicit layout"))).collect();
    let end = s.members.last().map(|m| m.offset.unwrap() + m.ty.nbyte().expect("sized member")).unwrap_or(0);
    let reflected = Reflected { members, size: stride.unwrap_or(end) };
    if let Some(previous) = out.get(name) {
        assert_eq!(previous, &reflected, "struct {name} is laid out differently in two places");
    }
    out.insert(name.to_owned(), reflected);
}

fn reflect_all() -> HashMap<String, Reflected> {
    let mut structs = HashMap::new();
    for shader in ml_shaders::ALL {
        let (file, spirv) = (shader.file, shader.spirv);
        let words: Vec<u32> = spirv.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let entries = ReflectConfig::new().spv(words).ref_all_rscs(true).reflect().unwrap_or_else(|e| panic!("{file}: {e}"));
        for entry in entries {
            for var in &entry.vars {
                collect(var.ty(), None, &mut structs);
            }
        }
    }
    structs
}

/// How the Rust struct differs from the shaders' layout, if it does.
fn mismatch<T: GpuLayout>(structs: &HashMap<String, Reflected>) -> Option<String> {
    let Some(reflected) = structs.get(T::GLSL_NAME) else { return Some(format!("no shader uses struct {}", T::GLSL_NAME)) };
    let rust: Vec<(String, usize)> = T::field_offsets().into_iter().map(|(n, o)| (n.to_owned(), o)).collect();
    if rust != reflected.members {
        return Some(format!("{}: Rust field offsets {rust:?}, shaders {:?}", T::GLSL_NAME, reflected.members));
    }
    let size = std::mem::size_of::<T>();
    (size != reflected.size).then(|| format!("{}: Rust size {size}, shaders {}", T::GLSL_NAME, reflected.size))
}

fn check<T: GpuLayout>(structs: &HashMap<String, Reflected>) {
    if let Some(problem) = mismatch::<T>(structs) {
        panic!("{problem}");
    }
}

#[test]
fn rust_mirrors_match_spirv_reflection() {
    let structs = reflect_all();
    check::<FrameUniforms>(&structs);
    check::<PointLight>(&structs);
    check::<ObjectPush>(&structs);
    check::<LayerObject>(&structs);
    check::<ShadowPush>(&structs);
    check::<OmniShadowPush>(&structs);
    check::<StageProbePush>(&structs);
    check::<ObjectData>(&structs);
    check::<LightCone>(&structs);
    check::<EnvironmentData>(&structs);
    check::<ClusterRange>(&structs);
    check::<LightGridFeedback>(&structs);
    check::<LightGridDispatch>(&structs);
    check::<Meshlet>(&structs);
    check::<Instance>(&structs);
    check::<CullCounters>(&structs);
    check::<LargeTriangle>(&structs);
    check::<DrawIndexedCommand>(&structs);
    check::<CullPush>(&structs);
    check::<OmniRasterPush>(&structs);
    check::<OmniRasterCounters>(&structs);
    check::<ShadowCubeTiles>(&structs);
    check::<RayNode>(&structs);
    check::<RayTriangle>(&structs);
    check::<RayInstance>(&structs);
}

/// Mistake 5 (docs/DESIGN.md#mistakes-we-avoid): the original demo's index list was a std140
/// uint array, 16 bytes per index. Ours is a std430 uint array: stride 4, as the Rust side
/// uploads it (`Vec<u32>`).
#[test]
fn light_index_list_is_packed() {
    let mut stride = None;
    for shader in ml_shaders::ALL {
        let words: Vec<u32> = shader.spirv.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        for entry in ReflectConfig::new().spv(words).ref_all_rscs(true).reflect().unwrap() {
            for var in &entry.vars {
                if let Type::Struct(s) = var.ty() {
                    for m in s.members.iter().filter(|m| m.name.as_deref() == Some("light_indices")) {
                        let Type::Array(a) = &m.ty else { panic!("light_indices is not an array") };
                        stride = a.stride;
                    }
                }
            }
        }
    }
    assert_eq!(stride, Some(4), "light_indices must be a tightly packed uint array");
}

#[test]
fn the_check_catches_a_moved_field() {
    // A Rust struct whose fields are swapped relative to PointLight must not pass.
    #[repr(C)]
    struct Swapped {
        color: [f32; 4],
        position_radius: [f32; 4],
    }
    impl GpuLayout for Swapped {
        const GLSL_NAME: &'static str = "PointLight";
        fn field_offsets() -> Vec<(&'static str, usize)> {
            vec![("color", std::mem::offset_of!(Swapped, color)), ("position_radius", std::mem::offset_of!(Swapped, position_radius))]
        }
    }
    let problem = mismatch::<Swapped>(&reflect_all()).expect("a swapped field must be reported");
    assert!(problem.contains("PointLight"), "{problem}");
}
