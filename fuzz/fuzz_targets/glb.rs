//! GLB bytes through the whole loader. An input that starts as a GLB gets its header's length
//! set to its size, so that mutations reach the chunks behind the header instead of stopping
//! at a length that no longer matches (the gltf target keeps the header as it comes).
#![no_main]

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mut bytes = data.to_vec();
    if bytes.len() >= 12 && bytes.starts_with(b"glTF") {
        let length = (bytes.len() as u32).to_le_bytes();
        bytes[8..12].copy_from_slice(&length);
    }
    let _ = ml_cpu::gltf_scene::from_bytes(&bytes, Some(manylights_fuzz::folder()));
});
