//! What the fuzz targets share: a folder of files for the loaders to find (a glTF model, an
//! external buffer, an image), so that inputs which name files exercise the reading of
//! references — inside the folder, refused outside it — instead of failing for want of one.

use ml_cpu::gltf_writer::{png, quad, GltfWriter, PrimitiveData};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// A textured quad with a point light; its buffer and image are stored in it.
pub fn textured_quad() -> GltfWriter {
    let mut w = GltfWriter::new();
    let t = w.texture(png(2, 2, &[255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255]), "image/png");
    let m = w.textured_material(Some(t), None);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    let light = w.light(json!({ "type": "point", "intensity": 4.0 }));
    w.node(json!({ "translation": [0.0, 2.0, 0.0], "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
    w
}

/// The files of the folder: `quad.glb` (all in one), `quad.gltf` naming its buffer `quad.bin`
/// and its image `white.png` beside it, and those two.
pub fn folder_files() -> Vec<(&'static str, Vec<u8>)> {
    let glb = textured_quad().to_glb();
    let mut external = textured_quad();
    external.json["buffers"] = json!([{ "byteLength": external.bin.len(), "uri": "quad.bin" }]);
    external.json["images"][0] = json!({ "uri": "white.png" });
    vec![("quad.glb", glb), ("quad.gltf", external.to_gltf()), ("quad.bin", external.bin.clone()), ("white.png", png(1, 1, &[255; 4]))]
}

/// The folder the targets load relative to, under the system's temporary folder: one folder
/// that every process of a run shares (fork mode starts many), each file written beside its
/// place and renamed into it, so that no process reads another's half-written file.
pub fn folder() -> &'static Path {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join("manylights-fuzz-folder");
        std::fs::create_dir_all(&dir).expect("the fuzz folder");
        for (name, bytes) in folder_files() {
            let path = dir.join(name);
            if std::fs::read(&path).is_ok_and(|old| old == bytes) {
                continue;
            }
            let partial = dir.join(format!(".{name}.{}", std::process::id()));
            std::fs::write(&partial, bytes).expect("a file of the fuzz folder");
            std::fs::rename(&partial, &path).expect("a file of the fuzz folder");
        }
        dir
    })
}
