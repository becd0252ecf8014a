//! A small glTF 2.0 writer: the tests make every glTF file they load with it (no third-party
//! assets), and it makes the fuzzers' seed files. Meshes (positions, optional normals,
//! texture coordinates and u8/u16/u32 indices), materials (factors), nodes with a matrix or
//! TRS and children, point/spot/directional lights (KHR_lights_punctual), cameras. The JSON is
//! a `serde_json::Value`, so tests can break any part of it before writing.

use base64::Engine as _;
use serde_json::{json, Value};

/// Index types of an indexed primitive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IndexType {
    U8,
    U16,
    U32,
}

/// One triangle primitive.
#[derive(Clone, Debug, Default)]
pub struct PrimitiveData {
    pub positions: Vec<[f32; 3]>,
    pub normals: Option<Vec<[f32; 3]>>,
    pub uvs: Option<Vec<[f32; 2]>>,
    pub indices: Option<(Vec<u32>, IndexType)>,
    pub material: Option<usize>,
}

/// One of our meshes (positions, normals, texture coordinates, u32 indices) as a primitive
/// in `material`: how tests and the demo model write built-in meshes as glTF files.
pub fn mesh_primitive(mesh: &crate::mesh::Mesh, material: Option<usize>) -> PrimitiveData {
    PrimitiveData {
        positions: mesh.vertices.iter().map(|v| v.position).collect(),
        normals: Some(mesh.vertices.iter().map(|v| v.normal).collect()),
        uvs: Some(mesh.vertices.iter().map(|v| v.uv).collect()),
        indices: Some((mesh.indices.clone(), IndexType::U32)),
        material,
    }
}

/// A glTF document under construction: JSON plus one binary buffer.
#[derive(Clone, Debug)]
pub struct GltfWriter {
    pub json: Value,
    pub bin: Vec<u8>,
}

impl Default for GltfWriter {
    fn default() -> Self {
        GltfWriter::new()
    }
}

impl GltfWriter {
    pub fn new() -> GltfWriter {
        GltfWriter {
            json: json!({
                "asset": { "version": "2.0", "generator": "manylights gltf_writer" },
                "scene": 0,
                "scenes": [{ "nodes": [] }],
                "nodes": [], "meshes": [], "materials": [], "accessors": [], "bufferViews": [], "buffers": []
            }),
            bin: Vec::new(),
        }
    }

    fn push(&mut self, key: &str, value: Value) -> usize {
        let list = self.json[key].as_array_mut().expect("a list");
        list.push(value);
        list.len() - 1
    }

    /// Append bytes as a buffer view (4-byte aligned) and an accessor over it.
    fn accessor(&mut self, bytes: Vec<u8>, count: usize, component: u32, kind: &str, extra: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = self.push("bufferViews", json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() }));
        self.bin.extend(bytes);
        let mut a = json!({ "bufferView": view, "componentType": component, "count": count, "type": kind });
        if let (Some(a), Some(extra)) = (a.as_object_mut(), extra.as_object()) {
            a.extend(extra.clone());
        }
        self.push("accessors", a)
    }

    fn floats<const N: usize>(&mut self, values: &[[f32; N]], kind: &str, min_max: bool) -> usize {
        let bytes = values.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let extra = if min_max {
            let lo: Vec<f32> = (0..N).map(|k| values.iter().map(|v| v[k]).fold(f32::MAX, f32::min)).collect();
            let hi: Vec<f32> = (0..N).map(|k| values.iter().map(|v| v[k]).fold(f32::MIN, f32::max)).collect();
            json!({ "min": lo, "max": hi })
        } else {
            json!({})
        };
        self.accessor(bytes, values.len(), 5126, kind, extra)
    }

    /// Make accessor `accessor` (of VEC3 floats) sparse: element indices[k] is replaced by
    /// values[k] (u16 indices).
    pub fn sparse(&mut self, accessor: usize, indices: &[u16], values: &[[f32; 3]]) {
        let mut view = |bytes: Vec<u8>| {
            while !self.bin.len().is_multiple_of(4) {
                self.bin.push(0);
            }
            let v = self.push("bufferViews", json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len() }));
            self.bin.extend(bytes);
            v
        };
        let index_view = view(indices.iter().flat_map(|i| i.to_le_bytes()).collect());
        let value_view = view(values.iter().flatten().flat_map(|f| f.to_le_bytes()).collect());
        self.json["accessors"][accessor]["sparse"] = json!({
            "count": indices.len(),
            "indices": { "bufferView": index_view, "componentType": 5123 },
            "values": { "bufferView": value_view },
        });
    }

    /// A mesh of `primitives`; returns its index.
    pub fn mesh(&mut self, primitives: &[PrimitiveData]) -> usize {
        let mut list = Vec::new();
        for p in primitives {
            let mut attributes = json!({ "POSITION": self.floats(&p.positions, "VEC3", true) });
            if let Some(n) = &p.normals {
                attributes["NORMAL"] = json!(self.floats(n, "VEC3", false));
            }
            if let Some(uv) = &p.uvs {
                attributes["TEXCOORD_0"] = json!(self.floats(uv, "VEC2", false));
            }
            let mut prim = json!({ "attributes": attributes, "mode": 4 });
            if let Some((indices, ty)) = &p.indices {
                let (bytes, component): (Vec<u8>, u32) = match ty {
                    IndexType::U8 => (indices.iter().map(|&i| i as u8).collect(), 5121),
                    IndexType::U16 => (indices.iter().flat_map(|&i| (i as u16).to_le_bytes()).collect(), 5123),
                    IndexType::U32 => (indices.iter().flat_map(|&i| i.to_le_bytes()).collect(), 5125),
                };
                prim["indices"] = json!(self.accessor(bytes, indices.len(), component, "SCALAR", json!({})));
            }
            if let Some(m) = p.material {
                prim["material"] = json!(m);
            }
            list.push(prim);
        }
        self.push("meshes", json!({ "primitives": list }))
    }

    /// A metallic-roughness material of these factors; returns its index.
    pub fn material(&mut self, base_colour: [f32; 4], metallic: f32, roughness: f32) -> usize {
        self.push(
            "materials",
            json!({ "pbrMetallicRoughness": { "baseColorFactor": base_colour, "metallicFactor": metallic, "roughnessFactor": roughness } }),
        )
    }

    /// A texture of these PNG (or other image) bytes, stored in the buffer; returns its index.
    /// Materials name it with `{"index": i}` (`textured_material`).
    pub fn texture(&mut self, image: Vec<u8>, mime_type: &str) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = self.push("bufferViews", json!({ "buffer": 0, "byteOffset": self.bin.len(), "byteLength": image.len() }));
        self.bin.extend(image);
        for key in ["images", "textures"] {
            if self.json[key].is_null() {
                self.json[key] = json!([]);
            }
        }
        let image = self.push("images", json!({ "bufferView": view, "mimeType": mime_type }));
        self.push("textures", json!({ "source": image }))
    }

    /// Give texture `texture` a sampler (glTF JSON: magFilter, minFilter, wrapS, wrapT).
    pub fn sampler(&mut self, texture: usize, sampler: Value) {
        if self.json["samplers"].is_null() {
            self.json["samplers"] = json!([]);
        }
        let s = self.push("samplers", sampler);
        self.json["textures"][texture]["sampler"] = json!(s);
    }

    /// A material with a base-colour texture and/or a normal map (texture indices).
    pub fn textured_material(&mut self, base_colour: Option<usize>, normal: Option<usize>) -> usize {
        let m = self.material([1.0; 4], 0.0, 0.8);
        if let Some(t) = base_colour {
            self.json["materials"][m]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": t });
        }
        if let Some(t) = normal {
            self.json["materials"][m]["normalTexture"] = json!({ "index": t });
        }
        m
    }

    /// A node (any JSON: "mesh", "matrix", "translation", "children", …); returns its index.
    /// `root` puts it in the scene.
    pub fn node(&mut self, node: Value, root: bool) -> usize {
        let i = self.push("nodes", node);
        if root {
            self.json["scenes"][0]["nodes"].as_array_mut().expect("a list").push(json!(i));
        }
        i
    }

    /// A KHR_lights_punctual light (any JSON: "type", "color", "intensity", "range", "spot");
    /// returns its index. Nodes name it with `"extensions": {"KHR_lights_punctual": {"light": i}}`.
    pub fn light(&mut self, light: Value) -> usize {
        if self.json["extensions"]["KHR_lights_punctual"]["lights"].is_null() {
            self.json["extensions"] = json!({ "KHR_lights_punctual": { "lights": [] } });
            self.json["extensionsUsed"] = json!(["KHR_lights_punctual"]);
        }
        let lights = self.json["extensions"]["KHR_lights_punctual"]["lights"].as_array_mut().expect("a list");
        lights.push(light);
        lights.len() - 1
    }

    /// A camera (any JSON); returns its index.
    pub fn camera(&mut self, camera: Value) -> usize {
        if self.json["cameras"].is_null() {
            self.json["cameras"] = json!([]);
        }
        self.push("cameras", camera)
    }

    /// The document as a .gltf file with the buffer embedded as a base64 data URI.
    pub fn to_gltf(&self) -> Vec<u8> {
        let mut json = self.json.clone();
        let data = base64::engine::general_purpose::STANDARD.encode(&self.bin);
        if json["buffers"].as_array().is_some_and(|b| b.is_empty()) {
            json["buffers"] = json!([{ "byteLength": self.bin.len(), "uri": format!("data:application/octet-stream;base64,{data}") }]);
        }
        serde_json::to_vec_pretty(&json).expect("serialisable")
    }

    /// The document as a .glb file (JSON chunk + BIN chunk).
    pub fn to_glb(&self) -> Vec<u8> {
        let mut json = self.json.clone();
        if json["buffers"].as_array().is_some_and(|b| b.is_empty()) {
            json["buffers"] = json!([{ "byteLength": self.bin.len() }]);
        }
        let mut text = serde_json::to_vec(&json).expect("serialisable");
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let mut bin = self.bin.clone();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let total = 12 + 8 + text.len() + 8 + bin.len();
        let mut out = Vec::with_capacity(total);
        out.extend(b"glTF");
        out.extend(2u32.to_le_bytes());
        out.extend((total as u32).to_le_bytes());
        out.extend((text.len() as u32).to_le_bytes());
        out.extend(b"JSON");
        out.extend(text);
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(b"BIN\0");
        out.extend(bin);
        out
    }
}

/// A unit quad in y = 0 facing +Y (two triangles, indexed), with texture coordinates.
pub fn quad() -> PrimitiveData {
    PrimitiveData {
        positions: vec![[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [-1.0, 0.0, 1.0], [1.0, 0.0, 1.0]],
        normals: Some(vec![[0.0, 1.0, 0.0]; 4]),
        uvs: Some(vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]]),
        indices: Some((vec![0, 2, 1, 1, 2, 3], IndexType::U16)),
        material: None,
    }
}

/// The cube [−1, 1]³ as 12 triangles without normals (flat normals are the loader's job).
pub fn cube_without_normals(indices: IndexType) -> PrimitiveData {
    let mesh = crate::mesh::cube(1.0);
    PrimitiveData {
        positions: mesh.vertices.iter().map(|v| v.position).collect(),
        normals: None,
        uvs: None,
        indices: Some((mesh.indices, indices)),
        material: None,
    }
}

/// RGBA8 texels (row 0 at the top) as a PNG file.
pub fn png(width: u32, height: u32, rgba: &[u8]) -> Vec<u8> {
    let mut out = std::io::Cursor::new(Vec::new());
    image::write_buffer_with_format(&mut out, rgba, width, height, image::ExtendedColorType::Rgba8, image::ImageFormat::Png)
        .expect("a PNG in memory");
    out.into_inner()
}

/// A 4×4 RGBA8 image of four 2×2 quarters: red, green / blue, white (bilinear taps near a
/// quarter's centre see one colour), for tests of textures.
pub fn quarters() -> Vec<u8> {
    let colour = |x: u32, y: u32| match (x / 2, y / 2) {
        (0, 0) => [255, 0, 0, 255],
        (1, 0) => [0, 255, 0, 255],
        (0, 1) => [0, 0, 255, 255],
        _ => [255, 255, 255, 255],
    };
    (0..16).flat_map(|i| colour(i % 4, i / 4)).collect()
}
