use super::*;
use crate::gltf_writer::{cube_without_normals, png, quad, GltfWriter, IndexType, PrimitiveData};
use serde_json::json;

fn load_bytes(bytes: &[u8]) -> Scene {
    from_bytes(bytes, None).unwrap_or_else(|e| panic!("{e}")).0
}

/// World position of a loaded object's mesh vertex `i`.
fn world_vertex(scene: &Scene, object: usize, i: usize) -> Vec3 {
    let o = &scene.objects[object];
    let mesh = scene.mesh(o.mesh).unwrap();
    o.transform.transform_point3(Vec3::from(mesh.vertices[i].position))
}

#[test]
fn a_quad_keeps_its_place_material_and_normals() {
    let mut w = GltfWriter::new();
    let m = w.material([0.2, 0.4, 0.6, 1.0], 0.25, 0.75);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh, "translation": [1.0, 2.0, 3.0], "scale": [2.0, 1.0, 1.0] }), true);
    // A URI's scheme is case-insensitive: "DATA:" is a data URI like "data:".
    let upper = String::from_utf8(w.to_gltf()).unwrap().replace("\"data:", "\"DATA:").into_bytes();
    assert!(String::from_utf8_lossy(&upper).contains("\"DATA:application"));
    for bytes in [w.to_gltf(), w.to_glb(), upper] {
        let s = load_bytes(&bytes);
        assert_eq!(s.objects.len(), 1);
        assert_eq!(s.objects[0].material, Material { albedo: Vec3::new(0.2, 0.4, 0.6), roughness: 0.75, metallic: 0.25 });
        // Corner (1, 0, 1) of the quad, scaled by 2 in x and moved.
        let mesh = s.mesh(s.objects[0].mesh).unwrap();
        let corner = (0..4).map(|i| world_vertex(&s, 0, i)).find(|p| p.x > 2.0 && p.z > 3.5).unwrap();
        assert!((corner - Vec3::new(3.0, 2.0, 4.0)).length() < 1e-5, "{corner}");
        assert!(mesh.vertices.iter().all(|v| v.normal == [0.0, 1.0, 0.0] && v.position.iter().all(|c| c.abs() <= 1.0 + 1e-6)));
        // The default camera sees it.
        let p = (s.camera.projection(1.0) * s.camera.view()).project_point3(Vec3::new(1.0, 2.0, 3.0));
        assert!(p.x.abs() < 1.0 && p.y.abs() < 1.0 && (0.0..1.0).contains(&p.z));
    }
}

#[test]
fn missing_normals_are_flat_for_every_index_type() {
    for ty in [IndexType::U8, IndexType::U16, IndexType::U32] {
        let mut w = GltfWriter::new();
        let mesh = w.mesh(&[cube_without_normals(ty)]);
        w.node(json!({ "mesh": mesh }), true);
        let s = load_bytes(&w.to_gltf());
        let m = s.mesh(s.objects[0].mesh).unwrap();
        assert_eq!(m.indices.len(), 36, "{ty:?}");
        assert_eq!(m.vertices.len(), 36, "flat: three vertices per triangle");
        for v in &m.vertices {
            // Each face's normal is its axis, pointing out of the cube.
            let n = Vec3::from(v.normal);
            let p = Vec3::from(v.position);
            assert!((n.abs().max_element() - 1.0).abs() < 1e-6 && n.dot(p) > 0.0, "{ty:?}: {n} at {p}");
        }
        // Tangents were computed (orthogonal to the normal).
        assert!(m.vertices.iter().all(|v| Vec3::from_slice(&v.tangent[..3]).dot(Vec3::from(v.normal)).abs() < 1e-5));
    }
}

#[test]
fn node_hierarchies_multiply_and_meshes_are_shared() {
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    let child = w.node(json!({ "mesh": mesh, "translation": [0.0, 0.0, 5.0] }), false);
    // A quarter turn about +Y: the child's +Z offset lands on +X.
    let half = std::f32::consts::FRAC_1_SQRT_2;
    w.node(json!({ "rotation": [0.0, half, 0.0, half], "children": [child], "mesh": mesh }), true);
    let s = load_bytes(&w.to_gltf());
    assert_eq!(s.objects.len(), 2);
    assert_eq!(s.meshes.len(), 1, "one primitive, loaded once");
    let centres: Vec<Vec3> = (0..2).map(|o| (0..4).map(|i| world_vertex(&s, o, i)).sum::<Vec3>() / 4.0).collect();
    assert!(centres.iter().any(|c| c.length() < 1e-5));
    assert!(centres.iter().any(|c| (*c - Vec3::new(5.0, 0.0, 0.0)).length() < 1e-5), "{centres:?}");
}

#[test]
fn lights_and_cameras_come_from_their_nodes() {
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    w.node(json!({ "mesh": mesh }), true);
    let point = w.light(json!({ "type": "point", "color": [1.0, 0.5, 0.25], "intensity": 2.0, "range": 7.0 }));
    let far = w.light(json!({ "type": "point", "intensity": 4.0 }));
    let spot = w.light(json!({ "type": "spot", "spot": {} }));
    for (light, at) in [(point, [0.0, 3.0, 0.0]), (far, [1.0, 1.0, 1.0]), (spot, [0.0, 1.0, 0.0])] {
        w.node(json!({ "translation": at, "extensions": { "KHR_lights_punctual": { "light": light } } }), true);
    }
    // A directional light turned a quarter about −X: its −Z points down (−Y).
    let sun = w.light(json!({ "type": "directional", "color": [1.0, 0.9, 0.8], "intensity": 2.0 }));
    let half = std::f32::consts::FRAC_1_SQRT_2;
    w.node(json!({ "rotation": [-half, 0.0, 0.0, half], "extensions": { "KHR_lights_punctual": { "light": sun } } }), true);
    let camera = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.05, "zfar": 80.0 } }));
    w.node(json!({ "camera": camera, "translation": [0.0, 1.0, 4.0] }), true);
    let (s, warnings) = from_bytes(&w.to_gltf(), None).unwrap();
    assert_eq!(s.lights.len(), 3);
    assert!(warnings.is_empty(), "{warnings:?}");
    // The spot keeps its cone (glTF's defaults: inner 0, outer π/4, along the node's −Z); the
    // point lights have none.
    assert_eq!(s.cones, vec![LightCone::NONE, LightCone::NONE, LightCone::spot(-Vec3::Z, 0.0, std::f32::consts::FRAC_PI_4)]);
    assert_eq!(s.lights[0], PointLight { position_radius: [0.0, 3.0, 0.0, 7.0], color: [2.0, 1.0, 0.5, 0.0] });
    // No range: where 4 / d² falls to 1/256, d = 32.
    assert_eq!(s.lights[1].position_radius, [1.0, 1.0, 1.0, 32.0]);
    assert_eq!(s.directional.len(), 1);
    assert!((s.directional[0].direction - (-Vec3::Y)).length() < 1e-5, "{:?}", s.directional[0]);
    assert_eq!(s.directional[0].color, Vec3::new(2.0, 1.8, 1.6));
    assert_eq!(s.camera.position, Vec3::new(0.0, 1.0, 4.0));
    assert!((s.camera.forward() - (-Vec3::Z)).length() < 1e-5);
    assert!((s.camera.fov_y_deg - 0.8f32.to_degrees()).abs() < 1e-4 && s.camera.near == 0.05 && s.camera.far == 80.0);
    // Any number of directional lights: the same sun on nine more nodes.
    for _ in 0..9 {
        w.node(json!({ "rotation": [-half, 0.0, 0.0, half], "extensions": { "KHR_lights_punctual": { "light": sun } } }), true);
    }
    assert_eq!(from_bytes(&w.to_gltf(), None).unwrap().0.directional.len(), 10);
}

#[test]
fn strips_fans_and_unindexed_triangles_become_lists() {
    let p = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]];
    for (mode, triangles) in [(4, 1), (5, 2), (6, 2)] {
        let mut w = GltfWriter::new();
        let positions = if mode == 4 { p[..3].to_vec() } else { p.clone() };
        let mesh = w.mesh(&[PrimitiveData {
            positions,
            normals: Some(vec![[0.0, 1.0, 0.0]; if mode == 4 { 3 } else { 4 }]),
            ..Default::default()
        }]);
        w.json["meshes"][mesh]["primitives"][0]["mode"] = json!(mode);
        w.node(json!({ "mesh": mesh }), true);
        let s = load_bytes(&w.to_gltf());
        assert_eq!(s.mesh(s.objects[0].mesh).unwrap().indices.len(), triangles * 3, "mode {mode}");
    }
}

#[test]
fn textures_are_decoded_once_per_use_in_their_colour_space() {
    use crate::gltf_writer::png;
    let mut w = GltfWriter::new();
    let checker = w.texture(png(2, 2, &[255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255]), "image/png");
    let bump = w.texture(png(1, 1, &[191, 128, 238, 255]), "image/png");
    let both = w.textured_material(Some(checker), Some(bump));
    let base_only = w.textured_material(Some(checker), None);
    let a = w.mesh(&[PrimitiveData { material: Some(both), ..quad() }]);
    let b = w.mesh(&[PrimitiveData { material: Some(base_only), ..quad() }]);
    w.node(json!({ "mesh": a }), true);
    w.node(json!({ "mesh": b, "translation": [3.0, 0.0, 0.0] }), true);
    let s = load_bytes(&w.to_glb());
    assert_eq!(s.textures.len(), 2, "the checker once, the normal map once");
    assert_eq!(s.objects[0].textures, ObjectTextures { base_color: Some(0), normal: Some(1), ..Default::default() });
    assert_eq!(s.objects[1].textures, ObjectTextures { base_color: Some(0), ..Default::default() });
    assert!(s.textures[0].srgb && !s.textures[1].srgb);
    assert_eq!((s.textures[0].width, s.textures[0].height), (2, 2));
    assert_eq!(&s.textures[0].rgba[4..8], &[0, 255, 0, 255]);
}

#[test]
fn every_material_texture_and_factor_and_sampler_is_read() {
    use crate::gltf_writer::png;
    use crate::textures::{Filter, TextureSampler, Wrap};
    let mut w = GltfWriter::new();
    let white = png(1, 1, &[255; 4]);
    let [base, normal, orm, emissive] = [0; 4].map(|_| w.texture(white.clone(), "image/png"));
    // The occlusion map is the metallic-roughness texture itself (glTF's packed ORM), read
    // once as linear data.
    w.sampler(base, json!({ "magFilter": 9728, "minFilter": 9984, "wrapS": 33071, "wrapT": 33648 }));
    w.sampler(orm, json!({ "minFilter": 9729 }));
    let m = w.textured_material(Some(base), Some(normal));
    w.json["materials"][m]["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({ "index": orm });
    w.json["materials"][m]["occlusionTexture"] = json!({ "index": orm, "strength": 0.25 });
    w.json["materials"][m]["emissiveTexture"] = json!({ "index": emissive });
    w.json["materials"][m]["emissiveFactor"] = json!([1.0, 0.5, 0.0]);
    w.json["materials"][m]["normalTexture"]["scale"] = json!(0.5);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    let (s, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let t = s.objects[0].textures;
    assert_eq!(t.metallic_roughness, t.occlusion);
    assert_eq!(t.bits(), 0b11111);
    assert_eq!(s.textures.len(), 4, "base, normal, ORM once, emissive");
    let srgb: Vec<bool> = t.slots().iter().flatten().map(|&i| s.textures[i as usize].srgb).collect();
    assert_eq!(srgb, [true, false, false, false, true]);
    let sampler = |i: Option<u32>| s.textures[i.unwrap() as usize].sampler;
    let nearest = TextureSampler {
        wrap_u: Wrap::ClampToEdge,
        wrap_v: Wrap::MirroredRepeat,
        mag: Filter::Nearest,
        min: Filter::Nearest,
        mipmap: Some(Filter::Nearest),
    };
    assert_eq!(sampler(t.base_color), nearest);
    assert_eq!(sampler(t.occlusion), TextureSampler { mipmap: None, ..TextureSampler::default() });
    assert_eq!(sampler(t.normal), TextureSampler::default());
    let x = s.objects[0].extras;
    assert_eq!((x.emissive, x.normal_scale, x.occlusion_strength), (Vec3::new(1.0, 0.5, 0.0), 0.5, 0.25));
}

#[test]
fn sparse_accessors_replace_their_elements() {
    // A quad whose last corner a sparse substitution moves from (1, 0, 1) to (1, 0, 3) (min and
    // max left stale: they are not trusted), and the same quad from an accessor without a
    // buffer view: zeros but for the substituted corners.
    let world_corners = |s: &Scene| -> Vec<Vec3> {
        let o = &s.objects[0];
        s.mesh(o.mesh).unwrap().vertices.iter().map(|v| o.transform.transform_point3(Vec3::from(v.position))).collect()
    };
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    let positions = w.json["meshes"][mesh]["primitives"][0]["attributes"]["POSITION"].as_u64().unwrap() as usize;
    w.sparse(positions, &[3], &[[1.0, 0.0, 3.0]]);
    w.node(json!({ "mesh": mesh }), true);
    let s = load_bytes(&w.to_glb());
    let corners = world_corners(&s);
    assert!(
        corners[3].abs_diff_eq(Vec3::new(1.0, 0.0, 3.0), 1e-5) && corners[0].abs_diff_eq(Vec3::new(-1.0, 0.0, -1.0), 1e-5),
        "{corners:?}"
    );

    w.json["accessors"][positions].as_object_mut().unwrap().remove("bufferView");
    w.sparse(positions, &[1, 2, 3], &[[2.0, 0.0, 0.0], [0.0, 0.0, 2.0], [2.0, 0.0, 2.0]]);
    let corners = world_corners(&load_bytes(&w.to_glb()));
    let want = [Vec3::ZERO, Vec3::new(2.0, 0.0, 0.0), Vec3::new(0.0, 0.0, 2.0), Vec3::new(2.0, 0.0, 2.0)];
    assert!(corners.iter().zip(want).all(|(c, w)| c.abs_diff_eq(w, 1e-5)), "{corners:?}");
}

#[test]
fn optional_extensions_we_do_not_read_are_named_in_a_warning() {
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    w.node(json!({ "mesh": mesh }), true);
    w.json["extensionsUsed"] = json!(["KHR_materials_iridescence", "KHR_texture_transform"]);
    let (_, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert_eq!(warnings, ["extension KHR_materials_iridescence is not supported; the file is read without it"]);
    w.json["extensionsRequired"] = json!(["KHR_materials_iridescence"]);
    let err = from_bytes(&w.to_glb(), None).unwrap_err().to_string();
    assert!(err.contains("KHR_materials_iridescence") && err.contains("does not support"), "{err}");
}

/// KHR_texture_transform (translation · rotation · scale, one per material: the base
/// colour's) and KHR_materials_emissive_strength are read.
#[test]
fn texture_transforms_and_emissive_strength_are_read() {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(2, 2, &[255; 16]), "image/png");
    let m = w.textured_material(Some(texture), None);
    let transform = json!({ "offset": [0.5, 0.25], "rotation": std::f32::consts::FRAC_PI_2, "scale": [2.0, 3.0] });
    w.json["materials"][m]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"] = json!({ "KHR_texture_transform": transform });
    w.json["materials"][m]["emissiveFactor"] = json!([0.5, 0.25, 0.0]);
    w.json["materials"][m]["extensions"] = json!({ "KHR_materials_emissive_strength": { "emissiveStrength": 4.0 } });
    w.json["extensionsUsed"] = json!(["KHR_texture_transform", "KHR_materials_emissive_strength"]);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    let (scene, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let x = &scene.objects[0].extras;
    assert_eq!(x.emissive, Vec3::new(2.0, 1.0, 0.0));
    // (1, 0) scaled to (2, 0), turned a quarter counter-clockwise to (0, 2), moved by the offset.
    let t = x.uv_transform;
    assert!(t.transform_point2(glam::Vec2::new(1.0, 0.0)).abs_diff_eq(glam::Vec2::new(0.5, 2.25), 1e-5), "{t:?}");
    assert!(t.transform_point2(glam::Vec2::new(0.0, 1.0)).abs_diff_eq(glam::Vec2::new(-2.5, 0.25), 1e-5), "{t:?}");
    // Another transform on another of its textures: the base colour's is kept, with a warning.
    w.json["materials"][m]["emissiveTexture"] = json!({ "index": texture });
    let (scene, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert_eq!(scene.objects[0].extras.uv_transform, t);
    assert!(warnings.len() == 1 && warnings[0].contains("different texture transforms"), "{warnings:?}");
    // A negative strength is refused.
    w.json["materials"][m]["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"] = json!(-1.0);
    let err = from_bytes(&w.to_glb(), None).unwrap_err().to_string();
    assert!(err.contains("emissive strength -1"), "{err}");
}

/// The PBR extensions' factors (ior, specular, clearcoat, sheen, unlit) become the object's
/// lobes and their textures its texture slots (colours sRGB, normals made unit); a factor
/// outside its range or a texture that is not there is refused in one line.
#[test]
fn material_extensions_are_read_into_lobes() {
    let mut w = GltfWriter::new();
    let image = w.texture(png(1, 1, &[200, 100, 50, 255]), "image/png");
    let m = w.material([0.8, 0.2, 0.1, 1.0], 0.0, 0.6);
    w.json["materials"][m]["extensions"] = json!({
        "KHR_materials_ior": { "ior": 2.0 },
        "KHR_materials_specular": { "specularFactor": 0.5, "specularColorFactor": [2.0, 1.0, 0.5], "specularTexture": { "index": image } },
        "KHR_materials_clearcoat": {
            "clearcoatFactor": 0.8, "clearcoatRoughnessFactor": 0.1, "clearcoatNormalTexture": { "index": image, "scale": 0.5 }
        },
        "KHR_materials_sheen": { "sheenColorFactor": [0.5, 0.4, 0.3], "sheenRoughnessFactor": 0.25, "sheenColorTexture": { "index": image } },
    });
    let names = ["KHR_materials_ior", "KHR_materials_specular", "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_unlit"];
    w.json["extensionsUsed"] = json!(names);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    let (scene, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let t = scene.objects[0].textures;
    assert!(t.any_lobe_texture() && t.clearcoat.is_none() && t.specular_color.is_none());
    let texels = |slot: Option<u32>| &scene.textures[slot.unwrap() as usize];
    assert!(!texels(t.specular).srgb && texels(t.sheen_color).srgb && !texels(t.clearcoat_normal).srgb);
    assert_eq!(texels(t.specular).rgba[..], [200, 100, 50, 255], "data as stored");
    let unit = crate::textures::unit_normal_texel([200, 100, 50, 255]);
    assert_eq!(texels(t.clearcoat_normal).rgba[..], unit, "a normal made unit");
    assert_eq!(scene.objects[0].extras.lobes.clearcoat_normal_scale, 0.5);
    let lobes = scene.objects[0].extras.lobes;
    let f0 = 1.0f32 / 9.0;
    assert!(lobes.dielectric_f0().abs_diff_eq(Vec3::new(2.0 * f0, f0, 0.5 * f0), 1e-6), "{lobes:?}");
    assert_eq!((lobes.specular, lobes.clearcoat, lobes.clearcoat_roughness, lobes.sheen_roughness), (0.5, 0.8, 0.1, 0.25));
    assert_eq!(lobes.sheen_color, Vec3::new(0.5, 0.4, 0.3));
    assert!(!lobes.unlit && lobes.any());
    // Unlit, required: read.
    w.json["materials"][m]["extensions"] = json!({ "KHR_materials_unlit": {} });
    w.json["extensionsRequired"] = json!(["KHR_materials_unlit"]);
    let (scene, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert!(warnings.is_empty() && scene.objects[0].extras.lobes.unlit, "{warnings:?}");
    for (ext, body, says) in [
        ("KHR_materials_ior", json!({ "ior": 0.5 }), "ior 0.5 must be 0 or from 1 to 100"),
        ("KHR_materials_ior", json!({ "ior": "glass" }), "ior is \"glass\"; it must be a number in [0, 100]"),
        (
            "KHR_materials_specular",
            json!({ "specularColorFactor": [1.0, -1.0, 0.0] }),
            "specularColorFactor is [1.0,-1.0,0.0]; it must be a number not below 0",
        ),
        ("KHR_materials_clearcoat", json!({ "clearcoatFactor": 1.5 }), "clearcoatFactor is 1.5; it must be a number in [0, 1]"),
        ("KHR_materials_sheen", json!({ "sheenColorFactor": [1.0, 1.0] }), "sheenColorFactor is [1.0,1.0]"),
        (
            "KHR_materials_sheen",
            json!({ "sheenColorTexture": { "index": 3 } }),
            "sheenColorTexture names texture 3, but there are 1 textures",
        ),
        ("KHR_materials_clearcoat", json!({ "clearcoatTexture": {} }), "clearcoatTexture names no texture (no index)"),
        (
            "KHR_materials_clearcoat",
            json!({ "clearcoatNormalTexture": { "index": 0, "scale": "x" } }),
            "clearcoatNormalTexture has scale \"x\"",
        ),
    ] {
        w.json["materials"][m]["extensions"] = json!({ ext: body });
        let err = from_bytes(&w.to_glb(), None).unwrap_err().to_string();
        assert!(err.contains("material 0") && err.contains(says) && !err.contains('\n'), "{err}");
    }
}

/// KHR_materials_transmission and _volume: the factor, the attenuation and the thickness,
/// scaled from the mesh's units to the world's by the node's scale; the object is transparent
/// whatever its alpha mode (blended in layers); the textures are read; bad factors refused.
#[test]
fn transmission_and_volume_are_read_and_make_the_object_transparent() {
    let mut w = GltfWriter::new();
    w.texture(png(1, 1, &[255; 4]), "image/png");
    let m = w.material([0.9, 0.6, 0.3, 1.0], 0.0, 0.2);
    w.json["materials"][m]["extensions"] = json!({
        "KHR_materials_transmission": { "transmissionFactor": 0.75, "transmissionTexture": { "index": 0 } },
        "KHR_materials_volume": { "thicknessFactor": 0.3, "attenuationDistance": 0.5, "attenuationColor": [1.0, 0.5, 0.25] },
    });
    w.json["extensionsUsed"] = json!(["KHR_materials_transmission", "KHR_materials_volume"]);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh, "scale": [2.0, 2.0, 2.0] }), true);
    let (scene, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let o = &scene.objects[0];
    assert!(o.textures.transmission.is_some() && o.textures.thickness.is_none());
    let lobes = o.extras.lobes;
    assert_eq!((lobes.transmission, lobes.attenuation_distance, lobes.attenuation_color), (0.75, 0.5, Vec3::new(1.0, 0.5, 0.25)));
    assert!((lobes.thickness - 0.6).abs() < 1e-6, "{lobes:?}");
    // 0.6 / 0.5 = 1.2 attenuation distances: colour^1.2.
    assert!(lobes.volume_transmittance().abs_diff_eq(Vec3::new(1.0, 0.5f32.powf(1.2), 0.25f32.powf(1.2)), 1e-6));
    assert!(o.extras.transparent() && o.extras.alpha_mode == AlphaMode::Opaque && scene.has_transparent_objects());
    for (ext, body, says) in [
        ("KHR_materials_transmission", json!({ "transmissionFactor": -0.1 }), "transmissionFactor is -0.1; it must be a number in [0, 1]"),
        ("KHR_materials_volume", json!({ "attenuationDistance": 0.0 }), "attenuationDistance is 0.0"),
        ("KHR_materials_volume", json!({ "attenuationColor": [1.0, 2.0, 0.0] }), "attenuationColor is [1.0,2.0,0.0]"),
    ] {
        w.json["materials"][m]["extensions"] = json!({ ext: body });
        let err = from_bytes(&w.to_glb(), None).unwrap_err().to_string();
        assert!(err.contains("material 0") && err.contains(says) && !err.contains('\n'), "{err}");
    }
}

/// KHR_mesh_quantization: the quad's positions as normalised i16, its normals as normalised
/// i8 and its texture coordinates as u8 integers load as the float quad does (positions and
/// normals; texture coordinates are the integers); without the extension such accessors are
/// refused.
#[test]
fn quantized_attributes_load_as_floats() {
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    w.node(json!({ "mesh": mesh }), true);
    let float_quad = load_bytes(&w.to_glb());
    let accessor = |w: &mut GltfWriter, bytes: Vec<u8>, component: u32, kind: &str, normalized: bool| {
        while !w.bin.len().is_multiple_of(4) {
            w.bin.push(0);
        }
        let views = w.json["bufferViews"].as_array_mut().unwrap();
        views.push(json!({ "buffer": 0, "byteOffset": w.bin.len(), "byteLength": bytes.len(), "byteStride": 8 }));
        let view = views.len() - 1;
        w.bin.extend(bytes);
        let accessors = w.json["accessors"].as_array_mut().unwrap();
        accessors.push(json!({ "bufferView": view, "componentType": component, "count": 4, "type": kind, "normalized": normalized }));
        accessors.len() - 1
    };
    // Each element padded to 8 bytes (attributes are 4-byte aligned).
    let pad = |e: Vec<u8>| -> Vec<u8> { e.into_iter().chain(std::iter::repeat(0)).take(8).collect() };
    let q = quad();
    let positions: Vec<u8> =
        q.positions.iter().flat_map(|p| pad(p.iter().flat_map(|&x| ((x * 32767.0) as i16).to_le_bytes()).collect())).collect();
    let normals: Vec<u8> = q.normals.unwrap().iter().flat_map(|n| pad(n.iter().map(|&x| (x * 127.0) as i8 as u8).collect())).collect();
    let uvs: Vec<u8> = q.uvs.unwrap().iter().flat_map(|t| pad(t.iter().map(|&x| (x * 3.0) as u8).collect())).collect();
    let p = accessor(&mut w, positions, 5122, "VEC3", true);
    w.json["accessors"][p]["min"] = json!([-1.0, 0.0, -1.0]);
    w.json["accessors"][p]["max"] = json!([1.0, 0.0, 1.0]);
    let n = accessor(&mut w, normals, 5120, "VEC3", true);
    let t = accessor(&mut w, uvs, 5121, "VEC2", false);
    w.json["meshes"][0]["primitives"][0]["attributes"] = json!({ "POSITION": p, "NORMAL": n, "TEXCOORD_0": t });
    let err = from_bytes(&w.to_glb(), None).unwrap_err().to_string();
    assert!(err.contains("POSITION") && err.contains("I16"), "{err}");
    w.json["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    w.json["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    let (scene, warnings) = from_bytes(&w.to_glb(), None).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    let (a, b) = (scene.mesh(scene.objects[0].mesh).unwrap(), float_quad.mesh(float_quad.objects[0].mesh).unwrap());
    for i in 0..4 {
        assert_eq!(world_vertex(&scene, 0, i), world_vertex(&float_quad, 0, i));
        assert_eq!(a.vertices[i].normal, b.vertices[i].normal);
        assert_eq!(a.vertices[i].uv, b.vertices[i].uv.map(|x| x * 3.0));
    }
}

/// KHR_materials_variants: a variant draws the material its mapping names, primitives it does
/// not map keep theirs; an unknown name is refused with the file's names.
#[test]
fn material_variants_pick_their_materials() {
    let mut w = GltfWriter::new();
    let own = w.material([1.0, 1.0, 1.0, 1.0], 0.0, 0.5);
    let red = w.material([1.0, 0.0, 0.0, 1.0], 0.0, 0.5);
    let mesh = w.mesh(&[PrimitiveData { material: Some(own), ..quad() }, PrimitiveData { material: Some(own), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    w.json["extensionsUsed"] = json!(["KHR_materials_variants"]);
    w.json["extensions"] = json!({ "KHR_materials_variants": { "variants": [{ "name": "plain" }, { "name": "red" }] } });
    w.json["meshes"][mesh]["primitives"][0]["extensions"] =
        json!({ "KHR_materials_variants": { "mappings": [{ "material": red, "variants": [1] }] } });
    let albedos = |variant: Option<&str>| -> Vec<Vec3> {
        let (scene, warnings) = from_bytes_as(&w.to_glb(), None, variant).unwrap();
        assert!(warnings.is_empty(), "{warnings:?}");
        scene.objects.iter().map(|o| o.material.albedo).collect()
    };
    assert_eq!(albedos(None), [Vec3::ONE, Vec3::ONE]);
    assert_eq!(albedos(Some("plain")), [Vec3::ONE, Vec3::ONE]);
    assert_eq!(albedos(Some("red")), [Vec3::X, Vec3::ONE]);
    let err = from_bytes_as(&w.to_glb(), None, Some("blue")).unwrap_err().to_string();
    assert_eq!(err, "there is no material variant 'blue' (the file has plain, red)");
    w.json["meshes"][mesh]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][0]["material"] = json!(7);
    let err = from_bytes_as(&w.to_glb(), None, Some("red")).unwrap_err().to_string();
    assert!(err.contains("mesh 0 primitive 0") && err.contains("material 7, but there are 2 materials"), "{err}");
}

/// `good` with its buffer in the file `name` of `folder` (and the JSON naming it as `uri`).
fn with_external_buffer(good: &GltfWriter, folder: &Path, name: &str, uri: &str) -> Vec<u8> {
    std::fs::write(folder.join(name), &good.bin).unwrap();
    let mut w = GltfWriter { json: good.json.clone(), bin: good.bin.clone() };
    w.json["buffers"] = json!([{ "byteLength": good.bin.len(), "uri": uri }]);
    w.to_gltf()
}

/// A quad with a base-colour texture whose image is the file `uri` names.
fn textured_by_uri(uri: &str) -> Vec<u8> {
    let mut w = GltfWriter::new();
    let t = w.texture(png(1, 1, &[255; 4]), "image/png");
    w.json["images"][0] = json!({ "uri": uri });
    let m = w.textured_material(Some(t), None);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    w.to_gltf()
}

fn quad_writer() -> GltfWriter {
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    w.node(json!({ "mesh": mesh }), true);
    w
}

/// A GLB, a glTF's buffer or an image that is a device or a pipe is refused at once, with
/// the line that says so: read whole, /dev/zero would fill the memory, and a pipe no one
/// writes to would wait forever.
#[cfg(unix)]
#[test]
fn devices_and_pipes_are_refused_at_once_as_file_buffer_or_image() {
    use crate::files::hostile::{fifo, folder, link, refused_at_once};
    let d = folder("gltf-devices");
    let not_regular = "not a regular file (a device, pipe or socket)";
    for file in [fifo(&d, "pipe.glb"), link(&d, "zero.glb", "/dev/zero"), PathBuf::from("/dev/zero"), PathBuf::from("/dev/urandom")] {
        refused_at_once(&file.display().to_string(), not_regular, || load(&file, None).map(drop));
    }
    fifo(&d, "pipe.bin");
    fifo(&d, "pipe.png");
    let good = quad_writer();
    let buffer = |uri: &str| from_bytes(&with_external_buffer(&good, &d, "ok.bin", uri), Some(&d)).map(drop);
    refused_at_once("pipe buffer", &format!("buffer 0: 'pipe.bin': it is {not_regular}"), || buffer("pipe.bin"));
    refused_at_once("image pipe", &format!("image 0: 'pipe.png': it is {not_regular}"), || {
        from_bytes(&textured_by_uri("pipe.png"), Some(&d)).map(drop)
    });
    // A link inside the folder to a device leads out of it.
    link(&d, "zero.bin", "/dev/zero");
    refused_at_once("link to /dev/zero", "'zero.bin': it leads out of the folder", || buffer("zero.bin"));
    // The file itself, inside, is read.
    assert!(buffer("ok.bin").is_ok());
}

/// Buffers and images are read only inside the glTF's folder: absolute paths, `..` that
/// climbs out (percent-encoded too) and links that end outside are refused, naming the
/// reference and nothing of the file outside; URIs with a scheme are never followed.
#[cfg(unix)]
#[test]
fn references_stay_inside_the_model_folder() {
    use crate::files::hostile::{folder, link};
    let d = folder("gltf-references");
    let model = d.join("model");
    std::fs::create_dir_all(model.join("data")).unwrap();
    // Outside: 12,345 bytes an error must not tell of.
    std::fs::write(d.join("secret.bin"), vec![7u8; 12_345]).unwrap();
    link(&model, "out.bin", d.join("secret.bin"));
    // A link to a file outside that does not exist, and one to a folder outside: answered as
    // the link to the file that does.
    link(&model, "gone.bin", d.join("missing.bin"));
    link(&model, "up", d.clone());
    let good = quad_writer();
    let buffer = |uri: &str| from_bytes(&with_external_buffer(&good, &model, "data/quad bin.bin", uri), Some(&model)).map(drop);
    for (uri, expected) in [
        ("../secret.bin", "'../secret.bin': it leads out of the folder of the file that names it"),
        ("data/../../secret.bin", "it leads out of the folder"),
        ("%2E%2E/secret.bin", "'%2E%2E/secret.bin': it leads out of the folder"),
        ("out.bin", "'out.bin': it leads out of the folder of the file that names it, or to no file, through a link"),
        ("gone.bin", "'gone.bin': it leads out of the folder of the file that names it, or to no file, through a link"),
        ("up/secret.bin", "'up/secret.bin': it leads out of the folder of the file that names it, or to no file, through a link"),
        ("up/missing.bin", "'up/missing.bin': it leads out of the folder of the file that names it, or to no file, through a link"),
        ("/etc/passwd", "'/etc/passwd': an absolute path"),
        ("%2Fetc%2Fpasswd", "an absolute path"),
        ("file:///etc/passwd", "never downloads"),
        ("file:/etc/passwd", "never downloads"),
        ("data/%zz.bin", "'data/%zz.bin' is not a valid URI"),
    ] {
        let e = buffer(uri).unwrap_err().to_string();
        assert!(e.contains(expected) && !e.contains("12345"), "{uri}: {e}");
    }
    let e = from_bytes(&textured_by_uri("../secret.bin"), Some(&model)).unwrap_err().to_string();
    assert!(e.contains("image 0: '../secret.bin': it leads out of the folder"), "{e}");
    // Inside, by any path and through links that stay inside: read.
    link(&model, "inside.bin", model.join("data/quad bin.bin"));
    for uri in ["data/quad%20bin.bin", "./data/../data/quad%20bin.bin", "inside.bin"] {
        buffer(uri).unwrap_or_else(|e| panic!("{uri}: {e}"));
    }
}

/// A buffer's data must be as long as its byteLength says, give or take the GLB binary chunk's
/// padding to 4 bytes; only the first buffer may be that chunk.
#[test]
fn buffers_must_be_as_long_as_they_claim() {
    let d = std::env::temp_dir().join(format!("ml-gltf-buffer-lengths-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let good = quad_writer();
    let json = |length: usize| {
        let mut w = GltfWriter { json: good.json.clone(), bin: good.bin.clone() };
        w.json["buffers"] = json!([{ "byteLength": length, "uri": "quad.bin" }]);
        w.to_gltf()
    };
    let mut long = good.bin.clone();
    long.extend([0; 4]);
    std::fs::write(d.join("quad.bin"), &long).unwrap();
    let n = good.bin.len();
    assert!(from_bytes(&json(n + 1), Some(&d)).is_ok(), "3 bytes of padding");
    let e = from_bytes(&json(n), Some(&d)).unwrap_err().to_string();
    assert_eq!(e, format!("buffer 0: holds {} bytes but claims {n} (more than 3 bytes of padding)", n + 4));
    let mut two = GltfWriter { json: good.json.clone(), bin: good.bin.clone() };
    two.json["buffers"] = json!([{ "byteLength": n }, { "byteLength": 4 }]);
    let e = from_bytes(&two.to_glb(), None).unwrap_err().to_string();
    assert!(e.contains("buffer 1: only the first buffer may be the GLB binary chunk"), "{e}");
    std::fs::remove_dir_all(&d).unwrap();
}

/// What the gltf crate's validation lets through and glTF forbids, or a file that does not
/// render: each refused with one line naming the node, accessor, light or camera.
#[test]
fn files_that_break_gltf_rules_or_ranges_are_refused() {
    let edit = |f: &dyn Fn(&mut GltfWriter)| {
        let mut w = quad_writer();
        f(&mut w);
        w
    };
    let gltf = |f: &dyn Fn(&mut GltfWriter)| edit(f).to_gltf();
    let light = |light: serde_json::Value, node: serde_json::Value| {
        gltf(&|w| {
            let l = w.light(light.clone());
            let mut n = node.clone();
            n["extensions"] = json!({ "KHR_lights_punctual": { "light": l } });
            w.node(n, true);
        })
    };
    let mut longer_glb = quad_writer().to_glb();
    longer_glb.extend([0; 8]);
    // The header's length matching the file, and the chunks not: a JSON chunk claiming more
    // than the file holds, 5 bytes after the binary chunk (not a chunk: its header alone is
    // 8), and chunks in the wrong order.
    let with_length = |mut glb: Vec<u8>| {
        let length = glb.len() as u32;
        glb[8..12].copy_from_slice(&length.to_le_bytes());
        glb
    };
    let mut long_json = quad_writer().to_glb();
    long_json[12..16].copy_from_slice(&100_000u32.to_le_bytes());
    let mut trailing = quad_writer().to_glb();
    trailing.extend([1, 2, 3, 4, 5]);
    let trailing = with_length(trailing);
    let good = quad_writer().to_glb();
    let json_length = u32::from_le_bytes(good[12..16].try_into().unwrap()) as usize;
    let (json, bin) = good[12..].split_at(8 + json_length);
    let swapped = with_length([&good[..12], bin, json].concat());
    // An extra chunk of an unknown type after the binary one is glTF's way to extend: read.
    let mut extended = quad_writer().to_glb();
    extended.extend([4, 0, 0, 0, b'X', b'T', b'R', b'A', 9, 9, 9, 9]);
    let extended = with_length(extended);
    assert!(from_bytes(&extended, None).is_ok(), "a GLB with an extra chunk after its binary chunk is refused");
    let mut same_point = quad_writer();
    for corner in 1..4 {
        let at = corner * 12;
        let first: [u8; 12] = same_point.bin[..12].try_into().unwrap();
        same_point.bin[at..at + 12].copy_from_slice(&first);
    }
    // An accessor of zeros but for one substitution, claiming 50 million of them.
    let mut zeros = quad_writer();
    zeros.sparse(0, &[1], &[[2.0, 0.0, 0.0]]);
    zeros.json["accessors"][0].as_object_mut().unwrap().remove("bufferView");
    zeros.json["accessors"][0]["count"] = json!(50_000_000);
    let cases: Vec<(Vec<u8>, &str)> = vec![
        (zeros.to_gltf(), "POSITION: 50000000 elements without a buffer view: more than the 1048576"),
        // Alignment: an f32 accessor two bytes into its view, a view two bytes into its buffer,
        // a stride that is no multiple of 4.
        (
            gltf(&|w| w.json["accessors"][0]["byteOffset"] = json!(2)),
            "byteOffset 2 (in a buffer view at 0, stride 12) is not a multiple of its components' 4 bytes",
        ),
        (gltf(&|w| w.json["bufferViews"][0]["byteOffset"] = json!(2)), "in a buffer view at 2"),
        (gltf(&|w| w.json["bufferViews"][0]["byteStride"] = json!(14)), "stride 14) is not a multiple"),
        (longer_glb, "the GLB header says"),
        (
            gltf(&|w| {
                w.json["nodes"][0]["matrix"] = json!([1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0]);
                w.json["nodes"][0]["translation"] = json!([1.0, 0.0, 0.0]);
            }),
            "node 0: it has a matrix and a translation, rotation or scale too",
        ),
        (gltf(&|w| w.json["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 0.0])), "node 0: its rotation's length is 0, not 1"),
        (gltf(&|w| w.json["nodes"][0]["rotation"] = json!([0.0, 0.0, 0.0, 2.0])), "node 0: its rotation's length is 2, not 1"),
        (long_json, "GLB chunk 0 (JSON) says 100000 bytes, but"),
        (trailing, "5 bytes after the last GLB chunk are not a chunk"),
        (swapped, "the first GLB chunk is BIN, not JSON"),
        (gltf(&|w| w.json["asset"]["version"] = json!("3.0")), "asset.version '3.0' is not glTF 2.x"),
        (gltf(&|w| w.json["asset"]["version"] = json!("2")), "asset.version '2' is not glTF 2.x"),
        (gltf(&|w| w.json["asset"]["version"] = json!("+2.0")), "is not glTF 2.x"),
        (gltf(&|w| w.json["asset"]["minVersion"] = json!("2.1")), "asset.minVersion '2.1'"),
        // Nodes: two parents, a root that is a child, a root named twice, cycles.
        (
            gltf(&|w| {
                let child = w.node(json!({}), false);
                w.json["nodes"][0]["children"] = json!([child]);
                w.node(json!({ "children": [child] }), true);
            }),
            "node 1 is a child of both node 0 and node 2",
        ),
        (gltf(&|w| w.json["nodes"][0]["children"] = json!([0, 0])), "node 0 is a child of both node 0 and node 0"),
        (
            gltf(&|w| {
                let child = w.node(json!({}), true);
                w.json["nodes"][0]["children"] = json!([child]);
            }),
            "scene 0: node 1 is one of its roots and a child of node 0",
        ),
        (gltf(&|w| w.json["scenes"][0]["nodes"] = json!([0, 0])), "scene 0: node 0 is named twice"),
        (
            gltf(&|w| {
                let a = w.node(json!({}), false);
                let b = w.node(json!({ "children": [a] }), false);
                w.json["nodes"][a]["children"] = json!([b]);
            }),
            "is its own ancestor",
        ),
        // Transforms: all zero, projective, scales out of range.
        (gltf(&|w| w.json["nodes"][0]["matrix"] = json!([0.0f32; 16].to_vec())), "node 0: its transform is singular"),
        (
            gltf(&|w| w.json["nodes"][0]["matrix"] = json!([1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])),
            "node 0: its transform is singular",
        ),
        (gltf(&|w| w.json["nodes"][0]["matrix"] = json!([1, 0, 0, 1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1])), "last row is not (0, 0, 0, 1)"),
        (gltf(&|w| w.json["nodes"][0]["scale"] = json!([1e38, 1.0, 1.0])), "node 0: its transform scales an axis by 1e38"),
        (gltf(&|w| w.json["nodes"][0]["scale"] = json!([1.0, 1e-38, 1.0])), "scales an axis by 1e-38"),
        // Places and sizes.
        (
            gltf(&|w| w.bin[0..4].copy_from_slice(&1e38f32.to_le_bytes())),
            "mesh 0 primitive 0: POSITION: element 0 is 1e38, beyond ±1000000",
        ),
        (
            gltf(&|w| w.json["nodes"][0]["translation"] = json!([999_999.5, 0.0, 0.0])),
            "the scene's objects reach 1000000.5, beyond ±1000000",
        ),
        (same_point.to_gltf(), "too small to render"),
        // Lights, cameras, materials.
        (
            light(json!({ "type": "point", "intensity": 1e38 }), json!({})),
            "light 0: colour × intensity must be finite, not negative and at most 1e7",
        ),
        (light(json!({ "type": "point", "range": 1e-38 }), json!({})), "light 0: range 1e-38 must lie in [1e-6, 1e7]"),
        (
            light(json!({ "type": "point" }), json!({ "translation": [1e38, 0.0, 0.0] })),
            "light 0: its node's position is not finite or lies beyond",
        ),
        (light(json!({ "type": "directional", "intensity": 1e38 }), json!({})), "light 0: a directional light needs"),
        (
            gltf(&|w| {
                let c = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 1e-38, "zfar": 80.0 } }));
                w.node(json!({ "camera": c }), true);
            }),
            "camera 0: yfov 0.8 rad, znear 1e-38, zfar 80: need 0 < yfov < π and 0 < znear < zfar, both in [1e-6, 1e7]",
        ),
        (
            gltf(&|w| {
                let c = w.camera(json!({ "type": "perspective", "perspective": { "yfov": 0.8, "znear": 0.1 } }));
                w.node(json!({ "camera": c, "translation": [0.0, 0.0, 1e38] }), true);
            }),
            "camera 0: its node's transform is not usable",
        ),
        (
            gltf(&|w| {
                let m = w.material([1.0; 4], 0.0, 0.5);
                w.json["materials"][m]["extensions"] = json!({ "KHR_materials_emissive_strength": { "emissiveStrength": 1e38 } });
                w.json["meshes"][0]["primitives"][0]["material"] = json!(m);
            }),
            "emissive strength 1e38 must be finite, not negative and at most 1e7",
        ),
    ];
    for (i, (bytes, expected)) in cases.into_iter().enumerate() {
        match from_bytes(&bytes, None) {
            Ok(_) => panic!("case {i} ('{expected}'): loaded"),
            Err(e) => assert!(e.to_string().contains(expected), "case {i}: '{expected}' missing from: {e}"),
        }
    }
}

/// A chain of nodes each named twice as a child, which drawn from every parent would be 2⁴⁰
/// quads, is refused at once; versions 2.x and a minVersion of 2.0 are read.
#[test]
fn shared_children_are_refused_at_once_and_later_minor_versions_read() {
    let mut w = quad_writer();
    let mut below = 0;
    for _ in 0..40 {
        below = w.node(json!({ "children": [below, below] }), false);
    }
    w.json["scenes"][0]["nodes"] = json!([below]);
    let start = std::time::Instant::now();
    let e = from_bytes(&w.to_gltf(), None).unwrap_err().to_string();
    assert!(e.contains("node 0 is a child of both node 1 and node 1"), "{e}");
    assert!(start.elapsed().as_secs_f32() < 1.0);
    let mut w = quad_writer();
    w.json["asset"] = json!({ "version": "2.1", "minVersion": "2.0" });
    from_bytes(&w.to_gltf(), None).unwrap_or_else(|e| panic!("{e}"));
}

/// What a viewer draws with a stand-in is drawn without it, and said: a texture whose file is
/// missing, KTX2, KTX and DDS images (named); skins,
/// animations and morph targets are not applied and each warns. An image of no format, a
/// broken PNG and a texture not let read (outside the folder) still refuse the model.
#[test]
fn missing_and_unreadable_textures_are_left_out_with_a_warning_and_motion_warns() {
    let d = std::env::temp_dir().join(format!("ml-gltf-left-out-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let loaded = |bytes: Vec<u8>| from_bytes(&bytes, Some(&d)).unwrap_or_else(|e| panic!("{e}"));
    let (scene, warnings) = loaded(textured_by_uri("gone.png"));
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].textures.base_color, None, "drawn with its factor alone");
    assert!(
        warnings.iter().any(|w| w.contains("base colour texture (image 0) is left out: its file 'gone.png' does not exist")),
        "{warnings:?}"
    );
    for (bytes, name) in [
        (b"\xABKTX 20\xBB\r\n\x1A\n....".to_vec(), "KTX2"),
        (b"\xABKTX 11\xBB\r\n\x1A\n....".to_vec(), "KTX"),
        (b"DDS |....".to_vec(), "DDS"),
    ] {
        let mut w = GltfWriter::new();
        let t = w.texture(bytes, "image/ktx2");
        let m = w.textured_material(Some(t), None);
        let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
        w.node(json!({ "mesh": mesh }), true);
        let (scene, warnings) = loaded(w.to_glb());
        assert!(scene.textures.is_empty(), "{name}");
        let said = format!("is left out: it is a {name} image, which manylights does not read");
        assert!(warnings.iter().any(|w| w.contains(&said)), "{name}: {warnings:?}");
    }
    // Bytes of no image format, broken data of a known one, and a file outside the folder
    // refuse the model.
    std::fs::write(d.join("noise.png"), b"not an image at all").unwrap();
    assert!(from_bytes(&textured_by_uri("noise.png"), Some(&d)).unwrap_err().to_string().contains("could not be determined"));
    let mut broken = png(2, 2, &[255; 16]);
    broken.truncate(broken.len() - 20);
    std::fs::write(d.join("broken.png"), broken).unwrap();
    assert!(from_bytes(&textured_by_uri("broken.png"), Some(&d)).is_err());
    assert!(from_bytes(&textured_by_uri("../outside.png"), Some(&d)).unwrap_err().to_string().contains("leads out of the folder"));
    // A skin on the node, an animation of it, a morph target on the mesh.
    let mut w = quad_writer();
    let times = w.floats(&[[0.0f32], [1.0]], "SCALAR", true);
    let moves = w.floats(&[[0.0f32, 0.0, 0.0], [0.0, 1.0, 0.0]], "VEC3", false);
    w.json["skins"] = json!([{ "joints": [0] }]);
    w.json["nodes"][0]["skin"] = json!(0);
    w.json["animations"] = json!([{
        "samplers": [{ "input": times, "output": moves }],
        "channels": [{ "sampler": 0, "target": { "node": 0, "path": "translation" } }]
    }]);
    let offsets = w.floats(&[[0.0f32, 0.1, 0.0]; 4], "VEC3", false);
    w.json["meshes"][0]["primitives"][0]["targets"] = json!([{ "POSITION": offsets }]);
    let (_, warnings) = loaded(w.to_glb());
    for said in ["1 skin(s) are not applied", "1 animation(s) are not played", "morph targets of 1 mesh(es) are not applied"] {
        assert!(warnings.iter().any(|w| w.contains(said)), "{said}: {warnings:?}");
    }
}

/// A PNG of `width` × `height` whose header says so and whose pixels are not there: enough
/// for the budget, which reads headers alone.
fn png_header(width: u32, height: u32) -> Vec<u8> {
    fn crc32(bytes: &[u8]) -> u32 {
        let mut crc = !0u32;
        for &b in bytes {
            crc ^= u32::from(b);
            for _ in 0..8 {
                crc = if crc & 1 != 0 { (crc >> 1) ^ 0xedb8_8320 } else { crc >> 1 };
            }
        }
        !crc
    }
    let mut chunk = b"IHDR".to_vec();
    chunk.extend(width.to_be_bytes());
    chunk.extend(height.to_be_bytes());
    chunk.extend([8, 6, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for chunk in [chunk, b"IDAT".to_vec(), b"IEND".to_vec()] {
        png.extend((chunk.len() as u32 - 4).to_be_bytes());
        png.extend(&chunk);
        png.extend(crc32(&chunk).to_be_bytes());
    }
    png
}

/// A file's textures together take at most MAX_TEXTURE_BYTES decoded (mips included), known
/// from each image's header before it is decoded: a 16384² image (1.3 GiB) fits alone and is
/// refused on top of 3 GiB, naming its size; small images pass.
#[test]
fn textures_are_held_to_a_budget_read_from_their_headers() {
    let big = png_header(16384, 16384);
    let need = 16384u64 * 16384 * 4 * 4 / 3;
    assert_eq!(within_texture_budget(&big, 0).unwrap(), need);
    let e = within_texture_budget(&big, 3 << 30).unwrap_err().to_string();
    assert!(e.contains("16384×16384") && e.contains("4096 MiB") && e.contains("3072 MiB taken"), "{e}");
    assert_eq!(within_texture_budget(&png(2, 2, &[0; 16]), 5).unwrap(), 5 + 2 * 2 * 4 * 4 / 3);
}

/// A JPEG the fuzzer found, on which the decoder multiplies past u32 (with overflow checks, as
/// in this test's build, a panic in the decoder): the model loads or is refused in one line,
/// never a panic.
#[test]
fn a_decoder_that_stops_is_an_error_not_a_crash() {
    let mut w = GltfWriter::new();
    let t = w.texture(include_bytes!("fixtures/decoder_overflow.jpg").to_vec(), "image/jpeg");
    let m = w.textured_material(Some(t), None);
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(json!({ "mesh": mesh }), true);
    match from_bytes(&w.to_glb(), None) {
        // Built with overflow checks (the tests' profile), the decoder panics: answered.
        Err(e) => assert!(e.to_string().contains("image 0: cannot decode it: its decoder stopped on malformed data"), "{e}"),
        // Without (release), its arithmetic wraps and it decodes something.
        Ok(_) => {
            let checked = cfg!(debug_assertions);
            assert!(!checked, "the decoder did not stop where overflow checks are on");
        }
    }
    // Any panic inside is answered None; a panic outside still unwinds.
    assert_eq!(crate::image_decode::guarded_decode(|| -> u32 { panic!("inside") }), None);
    assert!(std::panic::catch_unwind(|| panic!("outside")).is_err());
}
