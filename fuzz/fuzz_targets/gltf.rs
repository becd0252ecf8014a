//! glTF bytes (JSON; GLB too, though the glb target is the one for those) through the whole
//! loader: parsing, our validation, buffers and images named relative to the fixture folder,
//! mesh building. Any panic (ours or the gltf crate's) is a crash; errors are fine.
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let _ = ml_cpu::gltf_scene::from_bytes(data, Some(manylights_fuzz::folder()));
});
