//! Omnidirectional point-light shadows (SPEC §4, seed 003), the CPU half: the six cube-face
//! cameras of a light and which lights get a shadow cube. The faces follow seed 003's list
//! (+X up −Y, −X up −Y, +Y up +Z, −Y up −Z, +Z up −Y, −Z up −Y): with them, and a 90°
//! projection whose NDC y runs down the framebuffer (Vulkan rows), the texel a face renders a
//! direction into is the texel cube sampling fetches for that direction (tested against
//! `textures::cube_direction`, Vulkan's cube-map convention).

use crate::gpu_types::PointLight;
use glam::{Mat4, Vec3};

/// Forward and up of cube face `face` (+X, −X, +Y, −Y, +Z, −Z: Vulkan's layer order).
pub fn face_axes(face: u32) -> (Vec3, Vec3) {
    match face {
        0 => (Vec3::X, -Vec3::Y),
        1 => (-Vec3::X, -Vec3::Y),
        2 => (Vec3::Y, Vec3::Z),
        3 => (-Vec3::Y, -Vec3::Z),
        4 => (Vec3::Z, -Vec3::Y),
        _ => (-Vec3::Z, -Vec3::Y),
    }
}

/// View-projection of face `face` of a shadow cube at `light`: 90° square frustum from `near`
/// to `far`, depth 0..1. No Y flip: NDC y = −1 is framebuffer row 0, as cube texel row 0 is.
pub fn face_view_proj(light: Vec3, face: u32, near: f32, far: f32) -> Mat4 {
    let (forward, up) = face_axes(face);
    Mat4::perspective_rh(std::f32::consts::FRAC_PI_2, 1.0, near, far) * Mat4::look_at_rh(light, light + forward, up)
}

/// The `k` lights that get a shadow cube: the strongest as seen from `eye` — colour
/// luminance × radius over the distance from the eye to the light's sphere (ties: lower
/// index). Returns light indices, strongest first.
pub fn shadowed_lights(lights: &[PointLight], k: usize, eye: Vec3) -> Vec<u32> {
    let score = |l: &PointLight| {
        let p = l.position_radius;
        let luminance = 0.2126 * l.color[0] + 0.7152 * l.color[1] + 0.0722 * l.color[2];
        let gap = (Vec3::new(p[0], p[1], p[2]).distance(eye) - p[3]).max(0.0);
        luminance * p[3] / (1.0 + gap)
    };
    let mut order: Vec<u32> = (0..lights.len() as u32).collect();
    order.sort_by(|&a, &b| score(&lights[b as usize]).total_cmp(&score(&lights[a as usize])).then(a.cmp(&b)));
    order.truncate(k);
    order
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::textures::cube_direction;

    #[test]
    fn each_face_renders_a_direction_where_cube_sampling_reads_it() {
        let light = Vec3::new(1.0, 2.0, -3.0);
        let size = 16;
        for face in 0..6 {
            let m = face_view_proj(light, face, 0.05, 50.0);
            for (x, y) in [(0, 0), (15, 0), (0, 15), (7, 3), (12, 9)] {
                let d = cube_direction(face, x, y, size);
                let ndc = m.project_point3(light + d * 2.0);
                // Texel centre of (x, y) in NDC (row 0 at NDC y = −1).
                let expect = |i: u32| 2.0 * (i as f32 + 0.5) / size as f32 - 1.0;
                assert!((ndc.x - expect(x)).abs() < 1e-4 && (ndc.y - expect(y)).abs() < 1e-4, "face {face} texel ({x}, {y}): {ndc}");
                assert!((0.0..=1.0).contains(&ndc.z));
            }
        }
    }

    #[test]
    fn faces_follow_seed_003() {
        let expected = [
            (Vec3::X, -Vec3::Y),
            (-Vec3::X, -Vec3::Y),
            (Vec3::Y, Vec3::Z),
            (-Vec3::Y, -Vec3::Z),
            (Vec3::Z, -Vec3::Y),
            (-Vec3::Z, -Vec3::Y),
        ];
        for (face, axes) in expected.iter().enumerate() {
            assert_eq!(face_axes(face as u32), *axes);
        }
    }

    #[test]
    fn the_strongest_lights_near_the_eye_get_shadows() {
        let light = |x: f32, r: f32, c: f32| PointLight { position_radius: [x, 0.0, 0.0, r], color: [c, c, c, 0.0] };
        let lights = [light(50.0, 1.0, 1.0), light(2.0, 3.0, 1.0), light(5.0, 3.0, 0.1), light(1.0, 3.0, 1.0)];
        assert_eq!(shadowed_lights(&lights, 2, Vec3::ZERO), vec![1, 3]);
        assert_eq!(shadowed_lights(&lights, 10, Vec3::ZERO).len(), 4);
        assert!(shadowed_lights(&lights, 0, Vec3::ZERO).is_empty());
    }
}
