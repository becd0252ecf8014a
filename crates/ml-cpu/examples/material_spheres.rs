//! Writes a glTF of the PBR extensions manylights reads, made by our own code: five spheres on
//! a disc — plain, clear-coated, sheen, a high-ior dielectric with a tinted specular, unlit —
//! of one rough red base, without lights or camera (the default sky and rig light it), and a
//! material variant "blue" that turns the plain sphere blue. Usage: material_spheres OUT.glb
use ml_cpu::gltf_writer::{mesh_primitive, GltfWriter};
use ml_cpu::mesh::MeshKind;
use serde_json::{json, Value};

fn main() {
    let Some(out) = std::env::args().nth(1) else {
        eprintln!("usage: material_spheres OUT.glb");
        std::process::exit(2);
    };
    let mut w = GltfWriter::new();
    let disc = w.material([0.5, 0.5, 0.5, 1.0], 0.0, 0.8);
    let mesh = w.mesh(&[mesh_primitive(&MeshKind::Disc.build(), Some(disc))]);
    w.node(json!({ "mesh": mesh, "scale": [6.0, 6.0, 6.0] }), true);
    let blue = w.material([0.1, 0.2, 0.8, 1.0], 0.0, 0.5);
    let extensions: [(&str, Value); 5] = [
        ("", json!({})),
        ("KHR_materials_clearcoat", json!({ "clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.05 })),
        ("KHR_materials_sheen", json!({ "sheenColorFactor": [0.9, 0.7, 1.0], "sheenRoughnessFactor": 0.4 })),
        ("KHR_materials_specular", json!({ "specularFactor": 1.0, "specularColorFactor": [1.0, 1.6, 2.0] })),
        ("KHR_materials_unlit", json!({})),
    ];
    for (i, (name, body)) in extensions.iter().enumerate() {
        let m = w.material([0.7, 0.12, 0.08, 1.0], 0.0, 0.6);
        if !name.is_empty() {
            w.json["materials"][m]["extensions"] = json!({ *name: body });
        }
        if *name == "KHR_materials_specular" {
            w.json["materials"][m]["extensions"]["KHR_materials_ior"] = json!({ "ior": 2.4 });
        }
        let mesh = w.mesh(&[mesh_primitive(&MeshKind::Sphere.build(), Some(m))]);
        if i == 0 {
            w.json["meshes"][mesh]["primitives"][0]["extensions"] =
                json!({ "KHR_materials_variants": { "mappings": [{ "material": blue, "variants": [0] }] } });
        }
        w.node(json!({ "mesh": mesh, "translation": [i as f32 * 2.4 - 4.8, 1.0, 0.0] }), true);
    }
    w.json["extensions"] = json!({ "KHR_materials_variants": { "variants": [{ "name": "blue" }] } });
    let mut used: Vec<&str> = extensions.iter().map(|(n, _)| *n).filter(|n| !n.is_empty()).collect();
    used.extend(["KHR_materials_ior", "KHR_materials_variants"]);
    w.json["extensionsUsed"] = json!(used);
    std::fs::write(&out, w.to_glb()).unwrap_or_else(|e| {
        eprintln!("error: cannot write '{out}': {e}");
        std::process::exit(1);
    });
}
