//! The Utah teapot from Martin Newell's public-domain Bézier patches (1975), in the compact
//! 10-patch form with mirror symmetry that GLUT popularised: 127 control points, z up.
//! Tessellated here into 32 bicubic patches and turned to +Y up.

use crate::geometry::{grid_indices, orient_triangles_to_normals, vertex_uv, Mesh};
use glam::{Mat3, Vec3};

/// Control-point indices of the 10 source patches (rim, body ×2, lid ×2, bottom, handle ×2,
/// spout ×2).
const PATCHES: [[usize; 16]; 10] = [
    [102, 103, 104, 105, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15],
    [12, 13, 14, 15, 16, 17, 18, 19, 20, 21, 22, 23, 24, 25, 26, 27],
    [24, 25, 26, 27, 29, 30, 31, 32, 33, 34, 35, 36, 37, 38, 39, 40],
    [96, 96, 96, 96, 97, 98, 99, 100, 101, 101, 101, 101, 0, 1, 2, 3],
    [0, 1, 2, 3, 106, 107, 108, 109, 110, 111, 112, 113, 114, 115, 116, 117],
    [118, 118, 118, 118, 124, 122, 119, 121, 123, 126, 125, 120, 40, 39, 38, 37],
    [41, 42, 43, 44, 45, 46, 47, 48, 49, 50, 51, 52, 53, 54, 55, 56],
    [53, 54, 55, 56, 57, 58, 59, 60, 61, 62, 63, 64, 28, 65, 66, 67],
    [68, 69, 70, 71, 72, 73, 74, 75, 76, 77, 78, 79, 80, 81, 82, 83],
    [80, 81, 82, 83, 84, 85, 86, 87, 88, 89, 90, 91, 92, 93, 94, 95],
];

/// The first six patches are mirrored in x and y (a full turn), handle and spout only in y.
const FOUR_FOLD: usize = 6;

#[rustfmt::skip]
const POINTS: [[f32; 3]; 127] = [
    [0.2, 0.0, 2.7], [0.2, -0.112, 2.7], [0.112, -0.2, 2.7], [0.0, -0.2, 2.7],
    [1.3375, 0.0, 2.53125], [1.3375, -0.749, 2.53125], [0.749, -1.3375, 2.53125], [0.0, -1.3375, 2.53125],
    [1.4375, 0.0, 2.53125], [1.4375, -0.805, 2.53125], [0.805, -1.4375, 2.53125], [0.0, -1.4375, 2.53125],
    [1.5, 0.0, 2.4], [1.5, -0.84, 2.4], [0.84, -1.5, 2.4], [0.0, -1.5, 2.4],
    [1.75, 0.0, 1.875], [1.75, -0.98, 1.875], [0.98, -1.75, 1.875], [0.0, -1.75, 1.875],
    [2.0, 0.0, 1.35], [2.0, -1.12, 1.35], [1.12, -2.0, 1.35], [0.0, -2.0, 1.35],
    [2.0, 0.0, 0.9], [2.0, -1.12, 0.9], [1.12, -2.0, 0.9], [0.0, -2.0, 0.9],
    [-2.0, 0.0, 0.9], [2.0, 0.0, 0.45], [2.0, -1.12, 0.45], [1.12, -2.0, 0.45],
    [0.0, -2.0, 0.45], [1.5, 0.0, 0.225], [1.5, -0.84, 0.225], [0.84, -1.5, 0.225],
    [0.0, -1.5, 0.225], [1.5, 0.0, 0.15], [1.5, -0.84, 0.15], [0.84, -1.5, 0.15],
    [0.0, -1.5, 0.15], [-1.6, 0.0, 2.025], [-1.6, -0.3, 2.025], [-1.5, -0.3, 2.25],
    [-1.5, 0.0, 2.25], [-2.3, 0.0, 2.025], [-2.3, -0.3, 2.025], [-2.5, -0.3, 2.25],
    [-2.5, 0.0, 2.25], [-2.7, 0.0, 2.025], [-2.7, -0.3, 2.025], [-3.0, -0.3, 2.25],
    [-3.0, 0.0, 2.25], [-2.7, 0.0, 1.8], [-2.7, -0.3, 1.8], [-3.0, -0.3, 1.8],
    [-3.0, 0.0, 1.8], [-2.7, 0.0, 1.575], [-2.7, -0.3, 1.575], [-3.0, -0.3, 1.35],
    [-3.0, 0.0, 1.35], [-2.5, 0.0, 1.125], [-2.5, -0.3, 1.125], [-2.65, -0.3, 0.9375],
    [-2.65, 0.0, 0.9375], [-2.0, -0.3, 0.9], [-1.9, -0.3, 0.6], [-1.9, 0.0, 0.6],
    [1.7, 0.0, 1.425], [1.7, -0.66, 1.425], [1.7, -0.66, 0.6], [1.7, 0.0, 0.6],
    [2.6, 0.0, 1.425], [2.6, -0.66, 1.425], [3.1, -0.66, 0.825], [3.1, 0.0, 0.825],
    [2.3, 0.0, 2.1], [2.3, -0.25, 2.1], [2.4, -0.25, 2.025], [2.4, 0.0, 2.025],
    [2.7, 0.0, 2.4], [2.7, -0.25, 2.4], [3.3, -0.25, 2.4], [3.3, 0.0, 2.4],
    [2.8, 0.0, 2.475], [2.8, -0.25, 2.475], [3.525, -0.25, 2.49375], [3.525, 0.0, 2.49375],
    [2.9, 0.0, 2.475], [2.9, -0.15, 2.475], [3.45, -0.15, 2.5125], [3.45, 0.0, 2.5125],
    [2.8, 0.0, 2.4], [2.8, -0.15, 2.4], [3.2, -0.15, 2.4], [3.2, 0.0, 2.4],
    [0.0, 0.0, 3.15], [0.8, 0.0, 3.15], [0.8, -0.45, 3.15], [0.45, -0.8, 3.15],
    [0.0, -0.8, 3.15], [0.0, 0.0, 2.85], [1.4, 0.0, 2.4], [1.4, -0.784, 2.4],
    [0.784, -1.4, 2.4], [0.0, -1.4, 2.4], [0.4, 0.0, 2.55], [0.4, -0.224, 2.55],
    [0.224, -0.4, 2.55], [0.0, -0.4, 2.55], [1.3, 0.0, 2.55], [1.3, -0.728, 2.55],
    [0.728, -1.3, 2.55], [0.0, -1.3, 2.55], [1.3, 0.0, 2.4], [1.3, -0.728, 2.4],
    [0.728, -1.3, 2.4], [0.0, -1.3, 2.4], [0.0, 0.0, 0.0], [1.425, -0.798, 0.0],
    [1.5, 0.0, 0.075], [1.425, 0.0, 0.0], [0.798, -1.425, 0.0], [0.0, -1.5, 0.075],
    [0.0, -1.425, 0.0], [1.5, -0.84, 0.075], [0.84, -1.5, 0.075],
];

/// Cubic Bernstein basis and its derivative at t.
fn bernstein(t: f32) -> ([f32; 4], [f32; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [-3.0 * s * s, 3.0 * s * s - 6.0 * t * s, 6.0 * t * s - 3.0 * t * t, 3.0 * t * t],
    )
}

/// Point and (unnormalised) surface normal of a bicubic patch at (u, v).
fn eval(cp: &[Vec3; 16], u: f32, v: f32) -> (Vec3, Vec3) {
    let (bu, du) = bernstein(u);
    let (bv, dv) = bernstein(v);
    let (mut p, mut pu, mut pv) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
    for i in 0..4 {
        for j in 0..4 {
            let c = cp[i * 4 + j];
            p += bu[i] * bv[j] * c;
            pu += du[i] * bv[j] * c;
            pv += bu[i] * dv[j] * c;
        }
    }
    (p, pu.cross(pv))
}

/// Tessellate every patch (and its mirror images) into a (steps+1)² vertex grid.
pub(crate) fn teapot(steps: u32) -> Mesh {
    // z up → y up: (x, y, z) ↦ (x, z, −y), a rotation (no handedness change).
    let to_y_up = Mat3::from_cols(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 1.0, 0.0));
    let mut mesh = Mesh::default();
    for (index, patch) in PATCHES.iter().enumerate() {
        let mirrors: &[Vec3] = if index < FOUR_FOLD {
            &[Vec3::ONE, Vec3::new(-1.0, 1.0, 1.0), Vec3::new(1.0, -1.0, 1.0), Vec3::new(-1.0, -1.0, 1.0)]
        } else {
            &[Vec3::ONE, Vec3::new(1.0, -1.0, 1.0)]
        };
        for &mirror in mirrors {
            let cp: [Vec3; 16] = std::array::from_fn(|k| Vec3::from(POINTS[patch[k]]) * mirror);
            // A mirror image flips the parameterisation's handedness, so flip its normal too.
            // The source patches' (u × v) points inwards, hence the leading minus.
            let sign = -mirror.x * mirror.y;
            let base = mesh.vertices.len() as u32;
            for i in 0..=steps {
                for j in 0..=steps {
                    let (u, v) = (i as f32 / steps as f32, j as f32 / steps as f32);
                    let (p, mut n) = eval(&cp, u, v);
                    if n.length_squared() < 1e-12 {
                        // Collapsed edge (lid top, base centre): take the normal a step inside.
                        let nudge = |t: f32| t + (0.5 - t) * 1e-3;
                        n = eval(&cp, nudge(u), nudge(v)).1;
                    }
                    mesh.vertices.push(vertex_uv(to_y_up * p, to_y_up * (sign * n), [u, v]));
                }
            }
            grid_indices(base, steps, steps, &mut mesh.indices);
        }
    }
    orient_triangles_to_normals(&mut mesh)
}
