//! Image bytes as the base-colour texture of a textured quad (a GLB, the image in its binary
//! chunk), through the whole loader: format sniffing, the header's size checked against the
//! texture budget before decoding, the decode, the colour conversion. The mime type the file
//! claims follows the first byte, so that both decoders see their own and the other's bytes.
#![no_main]

use ml_cpu::gltf_writer::{quad, GltfWriter, PrimitiveData};
use serde_json::json;

libfuzzer_sys::fuzz_target!(|data: &[u8]| {
    let mime = if data.first() == Some(&0xff) { "image/jpeg" } else { "image/png" };
    let mut w = GltfWriter::new();
    let t = w.texture(data.to_vec(), mime);
    let m = w.textured_material(Some(t), None);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    let _ = ml_cpu::gltf_scene::from_bytes(&w.to_glb(), Some(manylights_fuzz::folder()));
});
