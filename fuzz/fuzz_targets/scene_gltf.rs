//! A scene file and the glTF file it places, mutated together: the input's first two bytes
//! (little-endian) say how long the scene file is, the rest is the glTF (GLB or JSON), written
//! as `pair.glb` and `pair.gltf` into a folder of this process beside the shared fixtures'
//! copies; the scene file is loaded from that folder. Any panic is a crash.
#![no_main]

use std::path::PathBuf;
use std::sync::OnceLock;

/// This process's folder: the fixtures (quad.glb, quad.gltf, …) and the input's glTF.
fn folder() -> &'static PathBuf {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("manylights-fuzz-pair-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("the fuzz folder");
        for (name, bytes) in manylights_fuzz::folder_files() {
            std::fs::write(dir.join(name), bytes).expect("a file of the fuzz folder");
        }
        dir
    })
}

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    if data.len() < 2 {
        return;
    }
    let split = (usize::from(u16::from_le_bytes([data[0], data[1]])) + 2).min(data.len());
    let (scene, gltf) = (&data[2..split], &data[split..]);
    let dir = folder();
    for name in ["pair.glb", "pair.gltf"] {
        std::fs::write(dir.join(name), gltf).expect("the input's glTF");
    }
    let _ = ml_cpu::scene_file::from_bytes(scene, Some(dir.as_path()));
});
