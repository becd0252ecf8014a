//! A small glTF 2.0 writer: the tests make every glTF file they load with it (no third-party
//! assets), and it makes the fuzzers' seed files. Meshes (positions, optional normals,
//! texture coordinates and u8/u16/u32 indices), materials (factors), nodes with a matrix or
//! TRS and children, point/spot/directional lights (KHR_lights_punctual), cameras, alpha modes
//! (OPAQUE, MASK with its cutoff, BLEND) and double-sided materials, and a cut-out texture with
//! holes (`cutout`) for alpha-mask tests. The JSON is a `serde_json::Value`, so tests can break
//! any part of it before writing.

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

    /// An accessor of float `values` ("SCALAR", "VEC2", …), with min and max where asked
    /// (POSITION and animation inputs need them); returns its index.
    pub fn floats<const N: usize>(&mut self, values: &[[f32; N]], kind: &str, min_max: bool) -> usize {
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

    /// Make accessor `accessor` (of VEC3 floats) sparse: element `indices[k]` is replaced by
    /// `values[k]` (u16 indices).
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

    /// Set material `material`'s `alphaMode` ("OPAQUE", "MASK" or "BLEND") and, where given,
    /// its `alphaCutoff` (else the file leaves it out: glTF's default, 0.5).
    pub fn alpha_mode(&mut self, material: usize, mode: &str, cutoff: Option<f32>) {
        let m = &mut self.json["materials"][material];
        m["alphaMode"] = json!(mode);
        if let Some(c) = cutoff {
            m["alphaCutoff"] = json!(c);
        }
    }

    /// Set material `material`'s `doubleSided`.
    pub fn double_sided(&mut self, material: usize, double_sided: bool) {
        self.json["materials"][material]["doubleSided"] = json!(double_sided);
    }

    /// Give material `material` a `name` (what the loader's messages call it).
    pub fn material_name(&mut self, material: usize, name: &str) {
        self.json["materials"][material]["name"] = json!(name);
    }

    /// A material whose base colour is `base_colour` (its alpha too) × texture `texture`, with
    /// `alphaMode` `mode` ("OPAQUE", "MASK", "BLEND"), `alphaCutoff` `cutoff` where given, and
    /// `doubleSided`; returns its index. With a `cutout` texture and MASK: a plate with holes.
    pub fn alpha_material(
        &mut self,
        texture: Option<usize>,
        base_colour: [f32; 4],
        mode: &str,
        cutoff: Option<f32>,
        double_sided: bool,
    ) -> usize {
        let m = self.material(base_colour, 0.0, 0.6);
        if let Some(t) = texture {
            self.json["materials"][m]["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": t });
        }
        self.alpha_mode(m, mode, cutoff);
        self.double_sided(m, double_sided);
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

/// Side of the `cutout` texture, in texels.
pub const CUTOUT_SIZE: u32 = 64;
/// The `cutout` texture's round holes, in texture coordinates (u right, v down): centre and
/// radius. With `CUTOUT_SLOT` they have no symmetry — a mirrored, turned or transposed lookup
/// puts holes where the plate is solid (`CUTOUT_SOLID`) and plate where the holes are.
pub const CUTOUT_DISCS: [([f32; 2], f32); 2] = [([0.28, 0.28], 0.17), ([0.75, 0.3], 0.1)];
/// Its rectangular hole: the corners (u, v) of least and greatest coordinates.
pub const CUTOUT_SLOT: [[f32; 2]; 2] = [[0.15, 0.66], [0.45, 0.84]];
/// Points well inside each hole (at least 0.09 from its edge), and well inside the plate.
pub const CUTOUT_HOLE_POINTS: [[f32; 2]; 3] = [[0.28, 0.28], [0.75, 0.3], [0.3, 0.75]];
pub const CUTOUT_SOLID: [[f32; 2]; 4] = [[0.75, 0.75], [0.5, 0.5], [0.06, 0.06], [0.75, 0.55]];

/// Whether texture coordinates `uv` lie in a hole of the `cutout` texture (its texel centres
/// are tested this way).
pub fn in_cutout_hole(uv: [f32; 2]) -> bool {
    let [lo, hi] = CUTOUT_SLOT;
    let slot = (lo[0]..hi[0]).contains(&uv[0]) && (lo[1]..hi[1]).contains(&uv[1]);
    slot || CUTOUT_DISCS.iter().any(|(c, r)| (uv[0] - c[0]).hypot(uv[1] - c[1]) < *r)
}

/// A CUTOUT_SIZE² RGBA8 texture (row 0 at the top) for alpha masks: a plate of colour `rgb`
/// with two round holes and a rectangular one (`CUTOUT_DISCS`, `CUTOUT_SLOT`), asymmetric so
/// that a lookup mirrored or turned anywhere shows. Alpha is 255 on the plate and 0 in the
/// holes; the colour is `rgb` everywhere, holes included, so that filtering (and mipmaps)
/// never bleed another colour into the plate's edges.
pub fn cutout(rgb: [u8; 3]) -> Vec<u8> {
    let n = CUTOUT_SIZE;
    (0..n * n)
        .flat_map(|i| {
            let uv = [((i % n) as f32 + 0.5) / n as f32, ((i / n) as f32 + 0.5) / n as f32];
            let alpha = if in_cutout_hole(uv) { 0 } else { 255 };
            [rgb[0], rgb[1], rgb[2], alpha]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::alpha_mask::{kept, texture_alpha};
    use crate::scene::AlphaMode;
    use glam::Vec2;

    /// The cut-out texture's holes lie where CUTOUT_DISCS and CUTOUT_SLOT say, it keeps its alpha through the
    /// PNG and the loader, and the alpha modes, cutoffs, base alphas and sides the writer gives
    /// materials are the ones the loader reads (BLEND with a warning naming the material).
    #[test]
    fn cutout_materials_round_trip_through_the_loader() {
        let texels = cutout([200, 100, 50]);
        assert_eq!(texels.len(), (CUTOUT_SIZE * CUTOUT_SIZE * 4) as usize);
        let holes = texels.chunks_exact(4).filter(|t| t[3] == 0).count();
        // π·(0.17² + 0.1²) + 0.3·0.18 of the texture's 4,096 texels: about 720.
        assert!((690..750).contains(&holes), "{holes} hole texels");
        // No symmetry: mirrored in u or v, turned half a turn or transposed, the holes move.
        let alpha = |x: u32, y: u32| texels[((y * CUTOUT_SIZE + x) * 4 + 3) as usize];
        let n = CUTOUT_SIZE - 1;
        let moved = |f: &dyn Fn(u32, u32) -> (u32, u32)| {
            (0..=n)
                .flat_map(|y| (0..=n).map(move |x| (x, y)))
                .filter(|&(x, y)| {
                    alpha(x, y) != {
                        let (a, b) = f(x, y);
                        alpha(a, b)
                    }
                })
                .count()
        };
        for (what, f) in [
            ("u mirrored", &(|x, y| (n - x, y)) as &dyn Fn(u32, u32) -> (u32, u32)),
            ("v mirrored", &|x, y| (x, n - y)),
            ("turned", &|x, y| (n - x, n - y)),
            ("transposed", &|x, y| (y, x)),
        ] {
            assert!(moved(f) > 200, "{what}: only {} texels change", moved(f));
        }
        assert!(texels.chunks_exact(4).all(|t| t[..3] == [200, 100, 50] && (t[3] == 0 || t[3] == 255)));
        let mut w = GltfWriter::new();
        let texture = w.texture(png(CUTOUT_SIZE, CUTOUT_SIZE, &texels), "image/png");
        let cases = [
            ("MASK", None, 1.0, true, AlphaMode::Mask { cutoff: 0.5 }),
            ("MASK", Some(0.3), 0.8, false, AlphaMode::Mask { cutoff: 0.3 }),
            ("BLEND", None, 0.6, true, AlphaMode::Blend),
            ("OPAQUE", None, 0.2, false, AlphaMode::Opaque),
        ];
        for (i, &(mode, cutoff, alpha, double_sided, _)) in cases.iter().enumerate() {
            let m = w.alpha_material(Some(texture), [1.0, 1.0, 1.0, alpha], mode, cutoff, double_sided);
            w.material_name(m, &format!("case-{i}"));
            let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
            w.node(json!({ "mesh": mesh, "translation": [3.0 * i as f32, 0.0, 0.0] }), true);
        }
        let (scene, warnings) = crate::gltf_scene::from_bytes(&w.to_glb(), None).expect("a good file");
        // BLEND is read as it is (blended by the renderer): nothing to warn of.
        assert!(warnings.is_empty(), "{warnings:?}");
        assert_eq!(scene.objects.len(), cases.len());
        for (o, &(_, _, alpha, double_sided, mode)) in scene.objects.iter().zip(&cases) {
            assert_eq!((o.extras.alpha_mode, o.extras.base_alpha, o.extras.double_sided), (mode, alpha, double_sided));
        }
        let t = &scene.textures[scene.objects[0].textures.base_color.expect("a base colour texture") as usize];
        assert_eq!(t.rgba.chunks_exact(4).map(|p| p[3]).collect::<Vec<_>>(), texels.chunks_exact(4).map(|p| p[3]).collect::<Vec<_>>());
        for h in CUTOUT_HOLE_POINTS {
            assert!(in_cutout_hole(h) && texture_alpha(t, Vec2::from(h)) == 0.0);
            for o in &scene.objects[..3] {
                assert!(!kept(o, &scene.textures, Vec2::from(h)), "{:?} keeps a hole", o.extras.alpha_mode);
            }
            assert!(kept(&scene.objects[3], &scene.textures, Vec2::from(h)), "opaque ignores alpha");
        }
        for s in CUTOUT_SOLID {
            assert!(!in_cutout_hole(s) && texture_alpha(t, Vec2::from(s)) == 1.0);
            assert!(scene.objects.iter().all(|o| kept(o, &scene.textures, Vec2::from(s))), "the plate at {s:?}");
        }
    }
}
