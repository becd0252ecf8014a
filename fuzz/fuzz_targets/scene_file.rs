//! Scene-file bytes through the parser and every check, its glTF objects named relative to
//! the fixture folder (which holds quad.glb and quad.gltf). Any panic is a crash.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = ml_cpu::scene_file::from_bytes(data, Some(manylights_fuzz::folder()));
});
