//! The framing camera (docs/scenes.md#the-framing-camera): the camera that shows a whole model
//! in an image of a given aspect, in a three-quarter view from above its front, as close as
//! the image allows but never inside, or just in front of, the model's box. Scene
//! files and glTF files without a camera of their own are seen from it, and the viewer's F key
//! frames the scene again with it. Apart from camera.rs because it reads a scene's vertices:
//! a scene holds a camera, so camera.rs takes no scene.

use crate::camera::Camera;
use crate::mesh::{Mesh, MeshKind};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// How far from a sphere of `radius` a camera of `fov_y_deg` stands to see all of it.
pub fn framing_distance(radius: f32, fov_y_deg: f32) -> f32 {
    radius / (fov_y_deg.to_radians() * 0.5).sin() * 1.05
}

/// The aspect ratio (width / height) a scene's framing camera is made for when the image's is
/// not known: the default image's, 1280×720.
pub const DEFAULT_ASPECT: f32 = 16.0 / 9.0;

/// The share of the image's width or height, whichever binds first, that a framed model
/// spans (the extent of its projected points, in NDC, over 2).
pub const FRAME_FILL: f32 = 0.8;
/// No framed point projects further from the image's centre than this (NDC), so that the
/// perspective's lopsided projection never cuts a model at the border.
pub const FRAME_REACH: f32 = 0.95;

/// Where a framing camera stands as seen from its target: a three-quarter view from above the
/// model's front (glTF's front is +Z): 30° round towards +X, 25° up. Off every axis, so that a
/// model built along one (a barrel, a boom, a deer's length) is not seen end on.
pub fn framing_direction() -> Vec3 {
    let (yaw, pitch) = (30f32.to_radians(), 25f32.to_radians());
    Vec3::new(yaw.sin() * pitch.cos(), pitch.sin(), yaw.cos() * pitch.cos())
}

/// How far in front of the model's box (along the framing direction, from the box's farthest
/// reach that way) a framing camera stands at least, in radii of the box's bounding sphere: a
/// part of the model reaching toward the camera (a boom, a barrel) then stays that far away,
/// and the camera never stands inside the model's bounds.
pub const MIN_CLEARANCE_RADII: f32 = 0.1;

/// A camera of `fov_y_deg` looking at the middle of `points`' box along `framing_direction`, as
/// close as it may stand for an image of `aspect` (width / height): the points' projections
/// span FRAME_FILL of the image's width or height, whichever binds first, and none lies beyond
/// FRAME_REACH of its centre — but MIN_CLEARANCE_RADII of its bounding sphere in front of the
/// box at least. The distance is found by bisection (both measures shrink as the camera
/// backs away); the near plane is half the camera's distance to the points' box, the far plane
/// past its far corner (`clip_planes_to_box`).
pub fn frame_points(points: &[Vec3], aspect: f32, fov_y_deg: f32) -> Camera {
    let (lo, hi) = points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let (lo, hi) = if points.is_empty() { (Vec3::splat(-1.0), Vec3::ONE) } else { (lo, hi) };
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-6);
    let back = framing_direction();
    let right = Vec3::Y.cross(back).normalize();
    let up = back.cross(right);
    // The points seen from a camera at the centre looking along −back: (x, y, how far towards the camera).
    let local: Vec<Vec3> = points.iter().map(|&p| p - centre).map(|q| Vec3::new(q.dot(right), q.dot(up), q.dot(back))).collect();
    let tan = (fov_y_deg.to_radians() * 0.5).tan();
    let (sx, sy) = (1.0 / (tan * aspect.max(1e-6)), 1.0 / tan);
    let nearest = local.iter().map(|q| q.z).fold(f32::MIN, f32::max).max(-radius);
    // The NDC box (x0, x1, y0, y1) of the points seen from distance d, the camera moved by
    // `shift` along its right and up axes, and the points that make its sides; None when a
    // point is not in front of the camera.
    let extent = |d: f32, shift: Vec2| {
        let mut e = ([f32::MAX, f32::MIN, f32::MAX, f32::MIN], [0usize; 4]);
        for (i, q) in local.iter().enumerate() {
            let depth = d - q.z;
            if depth <= 0.0 {
                return None;
            }
            let (x, y) = ((q.x - shift.x) * sx / depth, (q.y - shift.y) * sy / depth);
            for (side, v, lower) in [(0, x, true), (1, x, false), (2, y, true), (3, y, false)] {
                if (lower && v < e.0[side]) || (!lower && v > e.0[side]) {
                    (e.0[side], e.1[side]) = (v, i);
                }
            }
        }
        Some(e)
    };
    // Whether a camera at distance d frames the points loosely enough.
    let fits = |d: f32, shift: Vec2| match extent(d, shift) {
        None => false,
        Some(_) if local.is_empty() => true,
        Some(([x0, x1, y0, y1], _)) => {
            (x1 - x0).max(y1 - y0) * 0.5 <= FRAME_FILL && x0.abs().max(x1.abs()).max(y0.abs()).max(y1.abs()) <= FRAME_REACH
        }
    };
    // The least distance that fits, by bisection.
    let distance = |shift: Vec2| {
        let (mut near, mut far) = (nearest + radius * 1e-4, nearest.max(0.0) + radius * 2.0);
        for _ in 0..128 {
            if fits(far, shift) {
                break;
            }
            far *= 2.0;
        }
        // Down to a millionth of the distance (each step is a pass over every point): `far`
        // always fits.
        while far - near > far.abs() * 1e-6 {
            let mid = 0.5 * (near + far);
            if mid <= near || mid >= far {
                break;
            }
            if fits(mid, shift) {
                far = mid;
            } else {
                near = mid;
            }
        }
        far
    };
    // The perspective projects a box lopsidedly (its near side larger): move the camera
    // sideways until the projection is centred, so that the fill, not the reach, binds. The
    // shift that centres the two points making opposite sides (a at depth da, b at db):
    // (a − s)/da + (b − s)/db = 0.
    let mut shift = Vec2::ZERO;
    let mut d = distance(shift);
    for _ in 0..8 {
        let Some((_, [x0, x1, y0, y1])) = extent(d, shift).filter(|_| !local.is_empty()) else { break };
        let centred = |a: usize, b: usize, along: fn(&Vec3) -> f32| {
            let (da, db) = (d - local[a].z, d - local[b].z);
            (along(&local[a]) / da + along(&local[b]) / db) / (1.0 / da + 1.0 / db)
        };
        let next = Vec2::new(centred(x0, x1, |q| q.x), centred(y0, y1, |q| q.y));
        let settled = next.distance(shift) <= radius * 1e-4;
        shift = next;
        d = distance(shift);
        if settled {
            break;
        }
    }
    // Never closer than MIN_CLEARANCE_RADII in front of the box: backing away keeps the fit
    // (both measures shrink).
    let reach = ((hi - lo) * 0.5).dot(back.abs());
    let d = d.max(reach + radius * MIN_CLEARANCE_RADII);
    let position = centre + right * shift.x + up * shift.y + back * d;
    let (near, far) = clip_planes_to_box(lo, hi, position);
    Camera::looking_at(position, position - back * d, fov_y_deg, near, far)
}

/// `frame_points` of the box [lo, hi]'s eight corners.
pub fn frame_box(lo: Vec3, hi: Vec3, aspect: f32, fov_y_deg: f32) -> Camera {
    let corners: Vec<Vec3> = (0..8).map(|i| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo)).collect();
    frame_points(&corners, aspect, fov_y_deg)
}

/// Clip planes for a camera at `position` outside the box [lo, hi]: near half its distance to
/// the box (never under 1/2000 of the box's half diagonal), far 1.25 times its distance to the
/// box's farthest corner.
pub fn clip_planes_to_box(lo: Vec3, hi: Vec3, position: Vec3) -> (f32, f32) {
    let radius = ((hi - lo).length() * 0.5).max(1e-6);
    let gap = (lo - position).max(position - hi).max(Vec3::ZERO).length();
    let farthest = (position - lo).abs().max((position - hi).abs()).length();
    ((gap * 0.5).max(radius * 5e-4), farthest * 1.25)
}

/// The points a scene's framing camera fits: every vertex of every object, in world space
/// (every `stride`-th of an object's where the whole scene has more than FRAMING_POINTS, which
/// keeps framing a huge model quick).
pub fn framing_points(scene: &Scene) -> Vec<Vec3> {
    const FRAMING_POINTS: usize = 1 << 18;
    // Built-in meshes are made once each; a scene's own are its.
    let built: Vec<(MeshKind, Mesh)> =
        scene.mesh_kinds().into_iter().filter(|k| !matches!(k, MeshKind::Loaded(_))).map(|k| (k, k.build())).collect();
    let vertices = |kind: MeshKind| match kind {
        MeshKind::Loaded(i) => scene.meshes.get(i as usize).map(|m| &m.vertices[..]),
        builtin => built.iter().find(|(k, _)| *k == builtin).map(|(_, m)| &m.vertices[..]),
    };
    let total: usize = scene.objects.iter().map(|o| vertices(o.mesh).map_or(2, <[_]>::len)).sum();
    let stride = total.div_ceil(FRAMING_POINTS).max(1);
    let mut points = Vec::with_capacity(total / stride + 2 * scene.objects.len());
    for o in &scene.objects {
        match vertices(o.mesh) {
            Some(v) => points.extend(v.iter().step_by(stride).map(|v| o.transform.transform_point3(Vec3::from(v.position)))),
            None => points.extend(<[Vec3; 2]>::from(o.bounds())),
        }
    }
    points
}

/// The camera that frames `scene` for an image of `aspect` (`frame_points` of its vertices):
/// what a scene file or glTF file without a camera is seen from.
pub fn frame_scene(scene: &Scene, aspect: f32, fov_y_deg: f32) -> Camera {
    frame_points(&framing_points(scene), aspect, fov_y_deg)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Where `camera` puts `points` on an image of `aspect`: their NDC box (x0, x1, y0, y1).
    fn projected(camera: &Camera, points: &[Vec3], aspect: f32) -> (f32, f32, f32, f32) {
        let vp = camera.projection(aspect) * camera.view();
        points
            .iter()
            .map(|&p| vp.project_point3(p))
            .fold((f32::MAX, f32::MIN, f32::MAX, f32::MIN), |(a, b, c, d), n| (a.min(n.x), b.max(n.x), c.min(n.y), d.max(n.y)))
    }

    /// A framed box fills FRAME_FILL of the binding dimension at every aspect and size, none
    /// of it outside the image, in front of the near plane and behind the far one.
    #[test]
    fn a_framed_box_fills_the_binding_dimension_at_every_aspect() {
        let boxes = [
            (Vec3::splat(-1.0), Vec3::ONE),
            (Vec3::new(-3.0, 0.0, -0.5), Vec3::new(3.0, 0.2, 0.5)),
            (Vec3::new(0.0, 0.0, 0.0), Vec3::new(0.1, 5.0, 0.1)),
            (Vec3::new(-50.0, -1.0, -200.0), Vec3::new(50.0, 1.0, 200.0)),
        ];
        for (lo, hi) in boxes {
            for scale in [0.01f32, 1.0, 100.0] {
                for aspect in [16.0 / 9.0, 1.0, 9.0 / 16.0, 3.0] {
                    for fov in [30.0, 60.0, 90.0] {
                        let (lo, hi) = (lo * scale, hi * scale);
                        let camera = frame_box(lo, hi, aspect, fov);
                        let corners: Vec<Vec3> =
                            (0..8).map(|i| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo)).collect();
                        let (x0, x1, y0, y1) = projected(&camera, &corners, aspect);
                        let fill = (x1 - x0).max(y1 - y0) * 0.5;
                        let what = format!("{lo}..{hi} at {aspect:.2}, {fov}°: x {x0:.3}..{x1:.3}, y {y0:.3}..{y1:.3}");
                        // Filled as the image allows, or as close as the camera may stand.
                        let radius = (hi - lo).length() * 0.5;
                        let along = (camera.position - (lo + hi) * 0.5).dot(framing_direction());
                        let reach = ((hi - lo) * 0.5).dot(framing_direction().abs());
                        let closest = along <= (reach + radius * MIN_CLEARANCE_RADII) * 1.01;
                        assert!(fill <= FRAME_FILL + 1e-3 && (fill >= 0.7 || closest), "{what}: fills {fill}");
                        assert!([x0, x1, y0, y1].iter().all(|v| v.abs() <= FRAME_REACH + 1e-3), "{what}");
                        let vp = camera.projection(aspect) * camera.view();
                        for c in &corners {
                            let z = vp.project_point3(*c).z;
                            assert!((0.0..1.0).contains(&z), "{what}: depth {z}");
                        }
                        // Sane planes: the near one a good part of the way to the box.
                        assert!(camera.far / camera.near < 1e4, "{what}: planes {} .. {}", camera.near, camera.far);
                    }
                }
            }
        }
    }

    /// The camera looks along the framing direction, a wide image frames a cube by the height,
    /// a tall one by the width.
    #[test]
    fn framing_looks_at_the_box_and_binds_by_the_narrower_side() {
        let (lo, hi) = (Vec3::splat(-1.0), Vec3::ONE);
        let wide = frame_box(lo, hi, 16.0 / 9.0, 60.0);
        assert!(wide.forward().abs_diff_eq(-framing_direction(), 1e-5));
        let corners: Vec<Vec3> = (0..8).map(|i| Vec3::select(glam::BVec3::new(i & 1 != 0, i & 2 != 0, i & 4 != 0), hi, lo)).collect();
        let (x0, x1, y0, y1) = projected(&wide, &corners, 16.0 / 9.0);
        assert!(y1 - y0 > x1 - x0, "a cube in a wide image: the height binds");
        let tall = frame_box(lo, hi, 9.0 / 16.0, 60.0);
        assert!(tall.position.distance(Vec3::ZERO) > wide.position.distance(Vec3::ZERO), "a tall image stands further back");
    }

    /// A model with a long thin part (a space probe's boom) pointing straight at where the
    /// camera stands: framed whole, the camera outside the model's box and MIN_CLEARANCE_RADII
    /// from every point of it, the body a fair part of the image.
    #[test]
    fn a_boom_pointing_at_the_camera_does_not_pull_it_in() {
        let radius_of = |points: &[Vec3]| {
            let (lo, hi) = points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), &p| (lo.min(p), hi.max(p)));
            ((lo, hi), (hi - lo).length() * 0.5)
        };
        let body: Vec<Vec3> = (0..8).map(|i| Vec3::new([-1.0, 1.0][i & 1], [-0.6, 0.6][(i >> 1) & 1], [-0.8, 0.8][(i >> 2) & 1])).collect();
        for fov in [40.0, 60.0, 90.0] {
            // The boom: a thin line of points from the body toward the camera, 6 long.
            let mut points = body.clone();
            points.extend((1..=60).map(|k| framing_direction() * (0.1 * k as f32)));
            let ((lo, hi), radius) = radius_of(&points);
            let camera = frame_points(&points, 16.0 / 9.0, fov);
            let inside = camera.position.cmpge(lo).all() && camera.position.cmple(hi).all();
            assert!(!inside, "fov {fov}: the camera {} stands inside the model's box", camera.position);
            let nearest = points.iter().map(|p| p.distance(camera.position)).fold(f32::MAX, f32::min);
            assert!(nearest >= MIN_CLEARANCE_RADII * radius * 0.99, "fov {fov}: the camera is {nearest} from the model (radius {radius})");
            let (x0, x1, y0, y1) = projected(&camera, &points, 16.0 / 9.0);
            assert!([x0, x1, y0, y1].iter().all(|v| v.abs() <= FRAME_REACH + 1e-3), "fov {fov}: cut at the border");
            let (bx0, bx1, by0, by1) = projected(&camera, &body, 16.0 / 9.0);
            let body_fill = (bx1 - bx0).max(by1 - by0) * 0.5;
            println!("fov {fov}: nearest point {nearest:.2} (radius {radius:.2}), body fills {body_fill:.2}");
            assert!(body_fill > 0.1, "fov {fov}: the body is a speck ({body_fill})");
        }
    }
}
