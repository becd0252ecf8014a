//! glTF/GLB bytes through the whole loader: parsing, our validation, mesh building. Any
//! panic (ours or the gltf crate's) is a crash; errors are fine.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = ml_cpu::gltf_scene::from_bytes(data, None);
});
