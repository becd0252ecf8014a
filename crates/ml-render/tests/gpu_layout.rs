//! Every Rust struct shared with the shaders has the field offsets and size that SPIR-V
//! reflection of the compiled shaders reports (seed mistake 5: the std140 trap). A field
//! moved on either side fails here.

use ml_cpu::gpu_types::{FrameUniforms, GpuLayout, ObjectPush, PointLight};
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
    for (file, spirv) in ml_shaders::ALL {
        let words: Vec<u32> = spirv.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        let entries = ReflectConfig::new()
            .spv(words)
            .ref_all_rscs(true)
            .reflect()
            .unwrap_or_else(|e| panic!("{file}: {e}"));
        for entry in entries {
            for var in &entry.vars {
                collect(var.ty(), None, &mut structs);
            }
        }
    }
    structs
}

fn check<T: GpuLayout>(structs: &HashMap<String, Reflected>) {
    let reflected = structs.get(T::GLSL_NAME).unwrap_or_else(|| panic!("no shader uses struct {}", T::GLSL_NAME));
    let rust: Vec<(String, usize)> = T::field_offsets().into_iter().map(|(n, o)| (n.to_owned(), o)).collect();
    assert_eq!(rust, reflected.members, "{}: Rust field offsets differ from the shader's", T::GLSL_NAME);
    assert_eq!(std::mem::size_of::<T>(), reflected.size, "{}: Rust size differs from the shader's", T::GLSL_NAME);
}

#[test]
fn rust_mirrors_match_spirv_reflection() {
    let structs = reflect_all();
    check::<FrameUniforms>(&structs);
    check::<PointLight>(&structs);
    check::<ObjectPush>(&structs);
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
    let structs = reflect_all();
    assert!(std::panic::catch_unwind(|| check::<Swapped>(&structs)).is_err());
}
