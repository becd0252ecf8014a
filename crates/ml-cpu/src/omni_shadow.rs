//! Omnidirectional point-light shadows (docs/DESIGN.md#point-light-shadows), the CPU half: the
//! six cube-face cameras of a light and which lights get a shadow cube. The faces follow
//! Vulkan's cube layout (+X up −Y, −X up −Y, +Y up +Z, −Y up −Z, +Z up −Y, −Z up −Y): with
//! them, and a 90° projection whose NDC y runs down the framebuffer (Vulkan rows), the texel a
//! face renders a direction into is the texel cube sampling fetches for that direction (tested
//! against `textures::cube_direction`, Vulkan's cube-map convention).

use crate::camera::frustum_planes;
use crate::camera::Camera;
use crate::gpu_types::PointLight;
use crate::mesh::MeshKind;
use crate::scene::Scene;
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

/// The cube faces (bit i: face i, in `face_axes` order) whose 90° pyramid a sphere at
/// `centre` (relative to the light) of `radius` may reach: conservative, from the four
/// planes that bound each pyramid.
pub fn sphere_faces(centre: Vec3, radius: f32) -> u32 {
    let reach = radius * std::f32::consts::SQRT_2;
    let c = centre.to_array();
    let mut mask = 0;
    for face in 0..6 {
        let (axis, sign) = (face as usize / 2, if face % 2 == 0 { 1.0 } else { -1.0 });
        let along = sign * c[axis];
        let inside = (0..3).filter(|&o| o != axis).all(|o| along - c[o].abs() >= -reach);
        if inside {
            mask |= 1 << face;
        }
    }
    mask
}

/// The `k` lights that get a shadow cube: the strongest as seen from `eye` — colour
/// luminance × radius over the distance from the eye to the light's sphere (ties: lower
/// index). Returns light indices, strongest first.
pub fn shadowed_lights(lights: &[PointLight], k: usize, eye: Vec3) -> Vec<u32> {
    strongest_first(lights, (0..lights.len() as u32).collect(), k, eye)
}

/// The lights that reach the view of `camera` (aspect `aspect`) wherever their animation
/// moves them (by at most `motion` from their rest place): those whose sphere, grown by
/// `motion`, is not wholly outside one plane of the view frustum; the strongest `k` of them
/// (as `shadowed_lights` ranks), strongest first.
pub fn lights_in_view(lights: &[PointLight], camera: &Camera, aspect: f32, motion: f32, k: usize) -> Vec<u32> {
    let planes = frustum_planes(camera.projection(aspect) * camera.view());
    let seen = (0..lights.len() as u32)
        .filter(|&i| {
            let p = lights[i as usize].position_radius;
            let centre = Vec3::new(p[0], p[1], p[2]);
            planes.iter().all(|plane| plane.truncate().dot(centre) + plane.w >= -(p[3] + motion))
        })
        .collect();
    strongest_first(lights, seen, k, camera.position)
}

fn strongest_first(lights: &[PointLight], mut order: Vec<u32>, k: usize, eye: Vec3) -> Vec<u32> {
    let score = |l: &PointLight| {
        let p = l.position_radius;
        let luminance = 0.2126 * l.color[0] + 0.7152 * l.color[1] + 0.0722 * l.color[2];
        let gap = (Vec3::new(p[0], p[1], p[2]).distance(eye) - p[3]).max(0.0);
        luminance * p[3] / (1.0 + gap)
    };
    order.sort_by(|&a, &b| score(&lights[b as usize]).total_cmp(&score(&lights[a as usize])).then(a.cmp(&b)));
    order.truncate(k);
    order
}

/// A scene object as the CPU ray test sees it (analytic shapes of the built-in meshes).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Solid {
    Sphere {
        centre: Vec3,
        radius: f32,
    },
    /// A box seen from outside (the cube mesh).
    Block {
        lo: Vec3,
        hi: Vec3,
    },
    /// A box seen from inside (the room mesh): its walls face inwards and shadow nothing
    /// inside it (a box is convex).
    Room {
        lo: Vec3,
        hi: Vec3,
    },
}

/// The scene's objects as solids; None if one has a mesh the ray test does not model or a
/// transform other than a move and an even scale.
/// Blocks stacked face to face (a pillar of cubes) become one, so that shrinking it for the
/// margin does not open gaps between them.
pub fn solids(scene: &Scene) -> Option<Vec<Solid>> {
    let mut all: Vec<Solid> = scene
        .objects
        .iter()
        .map(|o| {
            let (c, s) = o.as_placed()?;
            match o.mesh {
                MeshKind::Sphere => Some(Solid::Sphere { centre: c, radius: s }),
                MeshKind::Cube => Some(Solid::Block { lo: c - Vec3::splat(s), hi: c + Vec3::splat(s) }),
                MeshKind::Room => Some(Solid::Room { lo: c - Vec3::splat(s), hi: c + Vec3::splat(s) }),
                _ => None,
            }
        })
        .collect::<Option<_>>()?;
    while let Some((i, j, merged)) = (0..all.len()).flat_map(|i| (0..all.len()).map(move |j| (i, j))).find_map(|(i, j)| {
        if i < j {
            merged_blocks(&all[i], &all[j]).map(|m| (i, j, m))
        } else {
            None
        }
    }) {
        all[i] = merged;
        all.remove(j);
    }
    Some(all)
}

/// Two blocks whose union is a box (equal in two axes, touching or overlapping in the third).
fn merged_blocks(a: &Solid, b: &Solid) -> Option<Solid> {
    let (Solid::Block { lo: alo, hi: ahi }, Solid::Block { lo: blo, hi: bhi }) = (*a, *b) else { return None };
    let same = (alo - blo).abs().cmple(Vec3::splat(1e-6)) & (ahi - bhi).abs().cmple(Vec3::splat(1e-6));
    let touch = alo.cmple(bhi + Vec3::splat(1e-6)) & blo.cmple(ahi + Vec3::splat(1e-6));
    let differing = (!same).bitmask().count_ones();
    (differing <= 1 && touch.all()).then(|| Solid::Block { lo: alo.min(blo), hi: ahi.max(bhi) })
}

/// Entry and exit distances of the ray (origin, unit dir) through the box, if it meets it.
fn slab(lo: Vec3, hi: Vec3, origin: Vec3, dir: Vec3) -> Option<(f32, f32, Vec3, Vec3)> {
    let inv = dir.recip();
    let (t0, t1) = ((lo - origin) * inv, (hi - origin) * inv);
    let (near, far) = (t0.min(t1), t0.max(t1));
    let (t_in, t_out) = (near.max_element(), far.min_element());
    if t_in > t_out || t_out < 0.0 {
        return None;
    }
    // The face crossed on entry and on exit: the axis that set each bound.
    let axis = |v: Vec3, t: f32| Vec3::select(v.cmpeq(Vec3::splat(t)), Vec3::ONE, Vec3::ZERO);
    let n_in = -axis(near, t_in) * dir.signum();
    let n_out = axis(far, t_out) * dir.signum();
    Some((t_in, t_out, n_in, n_out))
}

impl Solid {
    /// Nearest hit at distance > 0 along (origin, unit dir): distance and the normal there
    /// (towards the side the surface faces).
    pub fn hit(&self, origin: Vec3, dir: Vec3) -> Option<(f32, Vec3)> {
        match *self {
            Solid::Sphere { centre, radius } => {
                let oc = origin - centre;
                let b = oc.dot(dir);
                let disc = b * b - (oc.length_squared() - radius * radius);
                if disc < 0.0 {
                    return None;
                }
                let t = [-b - disc.sqrt(), -b + disc.sqrt()].into_iter().find(|&t| t > 0.0)?;
                Some((t, (origin + dir * t - centre) / radius))
            }
            Solid::Block { lo, hi } => slab(lo, hi, origin, dir).filter(|h| h.0 > 0.0).map(|h| (h.0, h.2)),
            Solid::Room { lo, hi } => slab(lo, hi, origin, dir).filter(|h| h.1 > 0.0).map(|h| (h.1, -h.3)),
        }
    }

    /// This solid grown (`by` > 0) or shrunk (`by` < 0) by `by` in every direction.
    fn grown(&self, by: f32) -> Solid {
        match *self {
            Solid::Sphere { centre, radius } => Solid::Sphere { centre, radius: (radius + by).max(0.0) },
            Solid::Block { lo, hi } => Solid::Block { lo: lo - Vec3::splat(by), hi: (hi + Vec3::splat(by)).max(lo - Vec3::splat(by)) },
            room => room,
        }
    }

    /// Whether it blocks the segment from `a` to `b`.
    fn blocks(&self, a: Vec3, b: Vec3) -> bool {
        let (dir, len) = ((b - a).normalize(), a.distance(b));
        match *self {
            Solid::Room { .. } => false,
            Solid::Sphere { centre, radius } => {
                let t = (centre - a).dot(dir).clamp(0.0, len);
                (a + dir * t).distance(centre) < radius
            }
            Solid::Block { lo, hi } => slab(lo, hi, a, dir).is_some_and(|(t_in, t_out, ..)| t_in < len && t_out > 0.0),
        }
    }
}

/// The first solid a ray meets: its index, distance and normal.
pub fn first_hit(solids: &[Solid], origin: Vec3, dir: Vec3) -> Option<(usize, f32, Vec3)> {
    solids.iter().enumerate().filter_map(|(i, s)| s.hit(origin, dir).map(|(t, n)| (i, t, n))).min_by(|a, b| a.1.total_cmp(&b.1))
}

/// What the CPU ray test says of a light at a surface point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sight {
    Lit,
    Shadowed,
    /// Within `margin` of a shadow edge: the shadow map's texels and filter decide.
    Unsure,
}

/// Whether `light` sees `point` (normal `n`): Shadowed if even the solids shrunk by `margin`
/// block the way, Lit if not even the solids grown by `margin` do (the segment starts
/// `2·margin` off the surface, so its own solid does not count), Unsure in between.
pub fn light_sight(solids: &[Solid], point: Vec3, n: Vec3, light: Vec3, margin: f32) -> Sight {
    let start = point + n * (2.0 * margin);
    if solids.iter().any(|s| s.grown(-margin).blocks(start, light)) {
        Sight::Shadowed
    } else if solids.iter().any(|s| s.grown(margin).blocks(start, light)) {
        Sight::Unsure
    } else {
        Sight::Lit
    }
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
    fn a_sphere_is_drawn_into_the_faces_it_reaches() {
        assert_eq!(sphere_faces(Vec3::new(5.0, 0.0, 0.0), 1.0), 0b000001);
        assert_eq!(sphere_faces(Vec3::new(0.0, -5.0, 0.0), 1.0), 0b001000);
        // On the +X/+Z edge: both faces.
        assert_eq!(sphere_faces(Vec3::new(5.0, 0.0, 5.0), 0.5), 0b010001);
        // Around the light: every face.
        assert_eq!(sphere_faces(Vec3::new(0.2, 0.0, 0.0), 1.0), 0b111111);
        // Every texel direction of a face lies in that face's pyramid: a tiny sphere there
        // is drawn into it.
        for face in 0..6 {
            for (x, y) in [(0, 0), (15, 15), (3, 12), (8, 8)] {
                let d = cube_direction(face, x, y, 16) * 4.0;
                assert!(sphere_faces(d, 1e-3) & (1 << face) != 0, "face {face} ({x}, {y})");
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
    fn the_ray_test_sees_walls_from_inside_and_blocks_behind_occluders() {
        let room = Solid::Room { lo: Vec3::splat(-5.0), hi: Vec3::splat(5.0) };
        let ball = Solid::Sphere { centre: Vec3::new(2.0, 0.0, 0.0), radius: 0.5 };
        let block = Solid::Block { lo: Vec3::new(-3.0, -5.0, -1.0), hi: Vec3::new(-2.0, -2.0, 0.0) };
        let all = [room, ball, block];
        // From the centre along +X: the ball first, then the wall facing back at us.
        assert_eq!(first_hit(&all, Vec3::ZERO, Vec3::X).map(|h| (h.0, h.1)), Some((1, 1.5)));
        let (i, t, n) = first_hit(&all, Vec3::ZERO, Vec3::Z).unwrap();
        assert_eq!((i, t, n), (0, 5.0, -Vec3::Z));
        let (i, t, n) = first_hit(&all, Vec3::new(-2.5, 0.0, -0.5), -Vec3::Y).unwrap();
        assert_eq!((i, t, n), (2, 2.0, Vec3::Y));
        let light = Vec3::ZERO;
        let wall = |p: Vec3| light_sight(&all, p, -p.normalize(), light, 0.05);
        assert_eq!(wall(Vec3::new(5.0, 0.0, 0.0)), Sight::Shadowed);
        assert_eq!(wall(Vec3::new(5.0, 0.0, 3.0)), Sight::Lit);
        // The ball's shadow edge on the +X wall: tangent rays at sin = 0.5 / 2.
        let edge = 5.0 * (0.25f32).asin().tan();
        assert_eq!(wall(Vec3::new(5.0, 0.0, edge)), Sight::Unsure);
        assert_eq!(wall(Vec3::new(5.0, 0.0, edge + 0.3)), Sight::Lit);
        assert_eq!(wall(Vec3::new(5.0, 0.0, edge - 0.3)), Sight::Shadowed);
        // The floor behind the block, and beside it.
        let floor = |x: f32, z: f32| light_sight(&all, Vec3::new(x, -5.0, z), Vec3::Y, light, 0.05);
        assert_eq!(floor(-4.0, -1.0), Sight::Shadowed);
        assert_eq!(floor(-4.0, 2.0), Sight::Lit);
        // The room's pillar of three cubes is one block.
        let room_solids = solids(&Scene::shadow_room()).unwrap();
        assert_eq!(room_solids.len(), 2);
        assert_eq!(room_solids[1], Solid::Block { lo: Vec3::new(1.0, -5.0, 0.0), hi: Vec3::new(2.0, -2.0, 1.0) });
    }

    #[test]
    fn the_strongest_lights_near_the_eye_get_shadows() {
        let light = |x: f32, r: f32, c: f32| PointLight { position_radius: [x, 0.0, 0.0, r], color: [c, c, c, 0.0] };
        let lights = [light(50.0, 1.0, 1.0), light(2.0, 3.0, 1.0), light(5.0, 3.0, 0.1), light(1.0, 3.0, 1.0)];
        assert_eq!(shadowed_lights(&lights, 2, Vec3::ZERO), vec![1, 3]);
        assert_eq!(shadowed_lights(&lights, 10, Vec3::ZERO).len(), 4);
        assert!(shadowed_lights(&lights, 0, Vec3::ZERO).is_empty());
    }

    #[test]
    fn lights_in_view_are_those_whose_moving_sphere_meets_the_frustum() {
        let light = |z: f32, r: f32| PointLight { position_radius: [0.0, 0.0, z, r], color: [1.0, 1.0, 1.0, 0.0] };
        let camera = Camera::looking_at(Vec3::ZERO, -Vec3::Z, 60.0, 0.1, 100.0);
        // In front; behind but reaching past the eye; behind out of reach; beyond the far
        // plane; behind, reached only by its motion.
        let lights = [light(-10.0, 1.0), light(3.0, 4.0), light(10.0, 1.0), light(-150.0, 10.0), light(2.5, 2.0)];
        assert_eq!(lights_in_view(&lights, &camera, 1.0, 0.0, 10), vec![1, 0]);
        assert_eq!(lights_in_view(&lights, &camera, 1.0, 1.0, 10), vec![1, 4, 0]);
        assert_eq!(lights_in_view(&lights, &camera, 1.0, 1.0, 1), vec![1]);
    }
}
