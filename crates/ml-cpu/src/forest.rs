//! A forest of cut-out leaves, made by our own code: trees of leaf cards (quads whose
//! base-colour texture's alpha cuts out the leaf shape, double-sided) around trunks on a
//! ground disc — the content alpha masks (`MASK`) and the transparent layers (`BLEND`: soft-
//! edged foliage) exist for, and the benchmark of their cost (`examples/forest.rs` writes it;
//! the tests render small ones). Each tree's mesh is stored once and placed by nodes, so the
//! file stays small whatever the count; the same arguments give the same bytes.

use crate::gltf_writer::{mesh_primitive, png, GltfWriter, IndexType, PrimitiveData};
use crate::mesh::MeshKind;
use serde_json::json;

/// Side of the leaf texture, in texels.
pub const LEAF_TEXELS: u32 = 128;

/// A leaf: an ellipse with a stem, notched along its edge; alpha 255 on it, 0 around it; the
/// colour is leaf green everywhere so that filtering never bleeds another colour in.
pub fn leaf_texture() -> Vec<u8> {
    let n = LEAF_TEXELS;
    (0..n * n)
        .flat_map(|i| {
            let (u, v) = (((i % n) as f32 + 0.5) / n as f32 * 2.0 - 1.0, ((i / n) as f32 + 0.5) / n as f32 * 2.0 - 1.0);
            let angle = v.atan2(u);
            let edge = 0.92 - 0.06 * (angle * 9.0).sin().abs();
            let inside = (u / 0.55).powi(2) + v.powi(2) < edge * edge || (u.abs() < 0.04 && v > 0.8);
            let vein = u.abs() < 0.025 && v.abs() < 0.85;
            let green: [u8; 3] = if vein { [120, 160, 60] } else { [50, 130 + ((v + 1.0) * 30.0) as u8, 40] };
            [green[0], green[1], green[2], if inside { 255 } else { 0 }]
        })
        .collect()
}

/// A small pseudo-random sequence (the file must be the same on every run).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// One tree's leaf cards: `leaves` quads of 0.5 m scattered through a crown 4 m across on a
/// trunk, each turned at random (one primitive, indexed).
fn crown(leaves: u32, seed: u64) -> PrimitiveData {
    let mut rng = Lcg(seed);
    let mut p = PrimitiveData { normals: Some(Vec::new()), uvs: Some(Vec::new()), ..PrimitiveData::default() };
    let mut indices = Vec::new();
    for _ in 0..leaves {
        // A point in the crown (an ellipsoid 4 m wide, 3 m tall, 4.5 m above the ground).
        let (mut x, mut y, mut z);
        loop {
            (x, y, z) = (rng.next() * 2.0 - 1.0, rng.next() * 2.0 - 1.0, rng.next() * 2.0 - 1.0);
            if x * x + y * y + z * z <= 1.0 {
                break;
            }
        }
        let centre = glam::Vec3::new(x * 2.0, 4.5 + y * 1.5, z * 2.0);
        let turn =
            glam::Quat::from_euler(glam::EulerRot::YXZ, rng.next() * std::f32::consts::TAU, rng.next() * 2.0 - 1.0, rng.next() * 1.2 - 0.6);
        let (right, up) = (turn * glam::Vec3::X * 0.25, turn * glam::Vec3::Y * 0.25);
        let normal = turn * glam::Vec3::Z;
        let first = p.positions.len() as u32;
        for (corner, uv) in [(-right - up, [0.0, 1.0]), (right - up, [1.0, 1.0]), (right + up, [1.0, 0.0]), (-right + up, [0.0, 0.0])] {
            p.positions.push((centre + corner).to_array());
            p.normals.as_mut().expect("set above").push(normal.to_array());
            p.uvs.as_mut().expect("set above").push(uv);
        }
        indices.extend([first, first + 1, first + 2, first, first + 2, first + 3]);
    }
    p.indices = Some((indices, IndexType::U32));
    p
}

/// The forest as a GLB file: `trees` trees (on a square grid, jittered, turned at random) of
/// `leaves` leaf cards each (two triangles a card), their material's `alpha_mode` (`MASK`,
/// `OPAQUE` or `BLEND`).
pub fn forest_glb(trees: u32, leaves: u32, alpha_mode: &str) -> Vec<u8> {
    let mut w = GltfWriter::new();
    let texture = w.texture(png(LEAF_TEXELS, LEAF_TEXELS, &leaf_texture()), "image/png");
    let leaf = w.alpha_material(Some(texture), [1.0; 4], alpha_mode, None, true);
    w.material_name(leaf, "leaf");
    let bark = w.material([0.35, 0.25, 0.18, 1.0], 0.0, 0.9);
    let ground = w.material([0.3, 0.36, 0.22, 1.0], 0.0, 0.95);
    // A few distinct crowns, each placed by many nodes (loaded once per mesh).
    let kinds: Vec<usize> = (0..4).map(|k| w.mesh(&[PrimitiveData { material: Some(leaf), ..crown(leaves, 17 + k) }])).collect();
    let trunk = w.mesh(&[mesh_primitive(&MeshKind::Cube.build(), Some(bark))]);
    let side = (trees as f32).sqrt().ceil() as u32;
    let spacing = 5.0;
    let mut rng = Lcg(5);
    for t in 0..trees {
        let (i, j) = ((t % side) as f32, (t / side) as f32);
        let at = [(i - side as f32 * 0.5) * spacing + rng.next() * 2.0, 0.0, (j - side as f32 * 0.5) * spacing + rng.next() * 2.0];
        let (s, c) = (rng.next() * std::f32::consts::PI).sin_cos();
        w.node(json!({ "mesh": kinds[t as usize % kinds.len()], "translation": at, "rotation": [0.0, s, 0.0, c] }), true);
        w.node(json!({ "mesh": trunk, "translation": [at[0], 1.75, at[2]], "scale": [0.15, 1.75, 0.15] }), true);
    }
    let disc = w.mesh(&[mesh_primitive(&MeshKind::Disc.build(), Some(ground))]);
    let half = side as f32 * spacing * 0.75;
    w.node(json!({ "mesh": disc, "scale": [half, half, half] }), true);
    w.to_glb()
}
