//! Seed files for the fuzzers (scripts/fuzz.sh): glTF/GLB files made by our writer and the
//! seed scene as a scene file. Usage: fuzz_seeds GLTF_DIR SCENE_DIR
use ml_cpu::gltf_writer::{cube_without_normals, png, quad, GltfWriter, IndexType, PrimitiveData};
use serde_json::json;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (gltf_dir, scene_dir) = match &args[..] {
        [_, g, s] => (std::path::PathBuf::from(g), std::path::PathBuf::from(s)),
        _ => {
            eprintln!("usage: fuzz_seeds GLTF_DIR SCENE_DIR");
            std::process::exit(2);
        }
    };
    std::fs::create_dir_all(&gltf_dir).expect("gltf seed folder");
    std::fs::create_dir_all(&scene_dir).expect("scene seed folder");
    let mut w = GltfWriter::new();
    let m = w.material([0.8, 0.2, 0.1, 1.0], 0.5, 0.4);
    let q = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    let c = w.mesh(&[cube_without_normals(IndexType::U8)]);
    let child = w.node(json!({ "mesh": c, "scale": [1.0, 2.0, 0.5] }), false);
    w.node(json!({ "mesh": q, "rotation": [0.0, 0.38268343, 0.0, 0.9238795], "children": [child] }), true);
    let light = w.light(json!({ "type": "point", "intensity": 3.0, "range": 9.0 }));
    w.node(json!({ "translation": [0.0, 3.0, 0.0], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
    let spot =
        w.light(json!({ "type": "spot", "intensity": 5.0, "range": 12.0, "spot": { "innerConeAngle": 0.2, "outerConeAngle": 0.5 } }));
    w.node(json!({ "translation": [1.0, 4.0, 0.0], "rotation": [-0.70710677, 0.0, 0.0, 0.70710677], "extensions": { "KHR_lights_punctual": { "light": spot } } }), true);
    let sun = w.light(json!({ "type": "directional", "intensity": 1.5 }));
    w.node(json!({ "rotation": [-0.3826834, 0.0, 0.0, 0.9238795], "extensions": { "KHR_lights_punctual": { "light": sun } } }), true);
    let camera = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.9, "znear": 0.1 } }));
    w.node(json!({ "camera": camera, "translation": [0.0, 1.0, 5.0] }), true);
    std::fs::write(gltf_dir.join("scene.gltf"), w.to_gltf()).expect("write");
    std::fs::write(gltf_dir.join("scene.glb"), w.to_glb()).expect("write");
    let mut strip = GltfWriter::new();
    let s =
        strip.mesh(&[PrimitiveData { positions: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]], ..Default::default() }]);
    strip.json["meshes"][s]["primitives"][0]["mode"] = json!(5);
    strip.node(json!({ "mesh": s, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 2, 0, 0, 1] }), true);
    std::fs::write(gltf_dir.join("strip.glb"), strip.to_glb()).expect("write");
    let mut textured = GltfWriter::new();
    let base = textured.texture(png(2, 2, &[255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255]), "image/png");
    let normal = textured.texture(png(1, 1, &[191, 128, 238, 255]), "image/png");
    let m = textured.textured_material(Some(base), Some(normal));
    // Every material texture, a sampler, the factors; a sparse accessor; an orthographic camera.
    textured.sampler(base, json!({ "magFilter": 9728, "minFilter": 9986, "wrapS": 33071, "wrapT": 33648 }));
    textured.json["materials"][m]["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({ "index": base });
    textured.json["materials"][m]["occlusionTexture"] = json!({ "index": base, "strength": 0.5 });
    textured.json["materials"][m]["emissiveTexture"] = json!({ "index": base });
    textured.json["materials"][m]["emissiveFactor"] = json!([1.0, 0.5, 0.0]);
    let q = textured.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    let positions = textured.json["meshes"][q]["primitives"][0]["attributes"]["POSITION"].as_u64().expect("an accessor") as usize;
    textured.sparse(positions, &[1, 3], &[[2.0, 0.0, -1.0], [2.0, 0.0, 1.0]]);
    textured.node(json!({ "mesh": q, "rotation": [0.70710677, 0.0, 0.0, 0.70710677] }), true);
    let ortho =
        textured.camera(json!({ "type": "orthographic", "orthographic": { "xmag": 2.0, "ymag": 2.0, "znear": 0.0, "zfar": 20.0 } }));
    textured.node(json!({ "camera": ortho, "translation": [0.0, 0.0, 5.0] }), true);
    std::fs::write(gltf_dir.join("textured.glb"), textured.to_glb()).expect("write");
    let seed = include_str!("../../../scenes/seed.toml");
    std::fs::write(scene_dir.join("seed.toml"), seed).expect("write");
    std::fs::write(scene_dir.join("small.toml"), "[camera]\nposition = [0.0, 2.0, 6.0]\northo_half_height = 3.0\n[shading]\nmodel = \"pbr\"\n[[lights]]\nposition = [1.0, 3.0, 2.0]\n[[lights]]\nkind = \"spot\"\nposition = [0.0, 4.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\ninner_deg = 10.0\nouter_deg = 25.0\n[[lights]]\nkind = \"directional\"\ndirection = [0.3, -1.0, 0.0]\n[[objects]]\nmesh = \"teapot\"\nmaterial = { name = \"gold\", roughness = 0.3 }\n").expect("write");
}
