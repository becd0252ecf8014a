//! Writes the README's demo model, made by our own code (the project ships no third-party
//! assets): a teapot, a torus knot and three spheres of several materials on a round table,
//! in centimetres (the table is 3 m across, so the file is 300 units wide) and without
//! lights or camera — a file as a user might bring. Usage: demo_model OUT.glb
use ml_cpu::gltf_writer::{mesh_primitive, GltfWriter};
use ml_cpu::mesh::MeshKind;
use serde_json::json;

fn main() {
    let Some(out) = std::env::args().nth(1) else {
        eprintln!("usage: demo_model OUT.glb");
        std::process::exit(2);
    };
    let mut w = GltfWriter::new();
    let mut add = |kind: MeshKind, colour: [f32; 3], metallic: f32, roughness: f32, at: [f32; 3], scale: f32, turn: f32| {
        let material = w.material([colour[0], colour[1], colour[2], 1.0], metallic, roughness);
        let mesh = w.mesh(&[mesh_primitive(&kind.build(), Some(material))]);
        let (s, c) = (turn * 0.5).sin_cos();
        w.node(json!({ "mesh": mesh, "translation": at, "scale": [scale, scale, scale], "rotation": [0.0, s, 0.0, c] }), true);
    };
    add(MeshKind::Disc, [0.55, 0.5, 0.45], 0.0, 0.6, [0.0, 0.0, 0.0], 150.0, 0.0);
    add(MeshKind::Teapot, [0.9, 0.9, 0.88], 0.0, 0.25, [-30.0, 40.0, 10.0], 40.0, 0.6);
    add(MeshKind::TorusKnot, [1.0, 0.766, 0.336], 1.0, 0.3, [60.0, 35.0, -40.0], 35.0, 0.0);
    add(MeshKind::Sphere, [0.7, 0.1, 0.1], 0.0, 0.4, [45.0, 18.0, 60.0], 18.0, 0.0);
    add(MeshKind::Sphere, [0.955, 0.637, 0.538], 1.0, 0.2, [-85.0, 14.0, -55.0], 14.0, 0.0);
    add(MeshKind::Sphere, [0.1, 0.3, 0.8], 0.0, 0.5, [-90.0, 20.0, 70.0], 20.0, 0.0);
    std::fs::write(&out, w.to_glb()).unwrap_or_else(|e| {
        eprintln!("error: cannot write '{out}': {e}");
        std::process::exit(1);
    });
}
