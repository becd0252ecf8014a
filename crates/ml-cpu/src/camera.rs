//! Camera (docs/DESIGN.md#conventions): right-handed, +Y up, view looks down −Z, Vulkan clip
//! space with Y flipped in the projection and depth 0..1; perspective, or orthographic (glTF).

use glam::{Mat4, Vec2, Vec3, Vec4};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub position: Vec3,
    /// Degrees above the horizon (negative looks down).
    pub pitch_deg: f32,
    /// Degrees from +X towards +Z in the ground plane.
    pub yaw_deg: f32,
    pub fov_y_deg: f32,
    pub near: f32,
    pub far: f32,
    /// Some(h): an orthographic camera seeing h world units above and below its axis (the
    /// width follows the image's aspect); fov_y_deg is then unused. None: perspective.
    pub orthographic: Option<f32>,
}

impl Camera {
    /// The seed scene's first-person camera, 62.5° down towards the grid. The demo it comes
    /// from calls `setPosition(10, 13, 1.8)`, but its framework stores the negated eye position
    /// (`camPos = camera.position * -1`) in a Y-down world; in our +Y-up world the eye is at
    /// (−10, 13, −1.8), facing +X.
    pub fn seed() -> Camera {
        Camera {
            position: Vec3::new(-10.0, 13.0, -1.8),
            pitch_deg: -62.5,
            yaw_deg: 0.0,
            fov_y_deg: 60.0,
            near: 0.1,
            far: 256.0,
            orthographic: None,
        }
    }

    /// A camera at `position` looking at `target`.
    pub fn looking_at(position: Vec3, target: Vec3, fov_y_deg: f32, near: f32, far: f32) -> Camera {
        let d = (target - position).normalize();
        Camera {
            position,
            pitch_deg: d.y.asin().to_degrees(),
            yaw_deg: d.z.atan2(d.x).to_degrees(),
            fov_y_deg,
            near,
            far,
            orthographic: None,
        }
    }

    pub fn forward(&self) -> Vec3 {
        let (p, y) = (self.pitch_deg.to_radians(), self.yaw_deg.to_radians());
        Vec3::new(p.cos() * y.cos(), p.sin(), p.cos() * y.sin())
    }

    pub fn view(&self) -> Mat4 {
        Mat4::look_to_rh(self.position, self.forward(), Vec3::Y)
    }

    /// Vulkan projection: glam's right-handed 0..1 depth perspective or orthographic
    /// projection with Y flipped.
    pub fn projection(&self, aspect: f32) -> Mat4 {
        let mut p = match self.orthographic {
            None => Mat4::perspective_rh(self.fov_y_deg.to_radians(), aspect, self.near, self.far),
            Some(h) => Mat4::orthographic_rh(-h * aspect, h * aspect, -h, h, self.near, self.far),
        };
        p.y_axis.y = -p.y_axis.y;
        p
    }

    /// Clip-space w at view depth d is `a·d + b`, (a, b) = this: (1, 0) for a perspective, (0, 1)
    /// for an orthographic projection (what the cluster code divides by).
    pub fn w_of_depth(&self) -> (f32, f32) {
        match self.orthographic {
            None => (1.0, 0.0),
            Some(_) => (0.0, 1.0),
        }
    }

    /// World-space ray (origin, unit direction) through the centre of pixel (x, y) of a
    /// width×height image whose row 0 is the top (Vulkan framebuffer order).
    pub fn pixel_ray(&self, x: u32, y: u32, width: u32, height: u32) -> (Vec3, Vec3) {
        let inv = (self.projection(width as f32 / height as f32) * self.view()).inverse();
        let ndc_x = (x as f32 + 0.5) / width as f32 * 2.0 - 1.0;
        let ndc_y = (y as f32 + 0.5) / height as f32 * 2.0 - 1.0;
        let unproject = |z: f32| {
            let p = inv * Vec4::new(ndc_x, ndc_y, z, 1.0);
            p.truncate() / p.w
        };
        let near = unproject(0.0);
        (near, (unproject(1.0) - near).normalize())
    }
}

/// A camera's field of view when nothing says otherwise (the seed's).
pub const DEFAULT_FOV_Y_DEG: f32 = 60.0;

/// Clip planes for a camera at `position` that sees the box [lo, hi] (a scene's): near half
/// the gap between the camera and the box's bounding sphere (never under 1/2000 of the
/// sphere's radius, for a camera inside it), far past the sphere's far side. Scene files and
/// `--camera` use these where they name no planes.
pub fn clip_planes_for(lo: Vec3, hi: Vec3, position: Vec3) -> (f32, f32) {
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo).length() * 0.5).max(1e-3);
    let distance = position.distance(centre);
    ((distance - radius).max(radius * 1e-3) * 0.5, distance + radius * 2.0)
}

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

/// Where a framing camera stands as seen from its target: above and in front (+Y, +Z).
pub fn framing_direction() -> Vec3 {
    Vec3::new(0.0, 0.5, 1.0).normalize()
}

/// A camera of `fov_y_deg` looking at the middle of `points`' box from above and in front
/// (`framing_direction`), as close as it may stand for an image of `aspect` (width / height):
/// the points' projections span FRAME_FILL of the image's width or height, whichever binds
/// first, and none lies beyond FRAME_REACH of its centre. The distance is found by bisection
/// (both measures shrink as the camera backs away); the near plane is half the camera's
/// distance to the points' box, the far plane past its far corner (`clip_planes_to_box`).
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
pub fn framing_points(scene: &crate::scene::Scene) -> Vec<Vec3> {
    use crate::mesh::MeshKind;
    const FRAMING_POINTS: usize = 1 << 18;
    // Built-in meshes are made once each; a scene's own are its.
    let built: Vec<(MeshKind, crate::mesh::Mesh)> =
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
pub fn frame_scene(scene: &crate::scene::Scene, aspect: f32, fov_y_deg: f32) -> Camera {
    frame_points(&framing_points(scene), aspect, fov_y_deg)
}

/// A camera as the command line gives it (`--camera EYE:TARGET[:FOV]`): where it stands,
/// what it looks at, its vertical field of view in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpec {
    pub position: Vec3,
    pub target: Vec3,
    pub fov_y_deg: f32,
}

/// Why a `--camera` text is not a camera.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CameraSpecError {
    #[error("camera '{0}' is not EYE_X,EYE_Y,EYE_Z:TARGET_X,TARGET_Y,TARGET_Z[:FOV_DEGREES] (finite numbers)")]
    Syntax(String),
    #[error("camera '{0}': the field of view must lie strictly between 0 and 180 degrees")]
    FieldOfView(String),
    #[error("camera '{0}': eye and target are the same point, so it looks nowhere")]
    Nowhere(String),
    #[error("camera '{0}' looks straight up or down, where its yaw is undefined: move the target sideways")]
    Vertical(String),
}

impl CameraSpec {
    /// Parse `EYE_X,EYE_Y,EYE_Z:TARGET_X,TARGET_Y,TARGET_Z[:FOV]` (fov in degrees, default 60).
    pub fn parse(text: &str) -> Result<CameraSpec, CameraSpecError> {
        let syntax = || CameraSpecError::Syntax(text.to_owned());
        let number = |s: &str| s.trim().parse::<f32>().ok().filter(|v| v.is_finite()).ok_or_else(syntax);
        let point = |s: &str| -> Result<Vec3, CameraSpecError> {
            let v = s.split(',').map(number).collect::<Result<Vec<f32>, _>>()?;
            <[f32; 3]>::try_from(v).map(Vec3::from).map_err(|_| syntax())
        };
        let parts: Vec<&str> = text.split(':').collect();
        let (position, target, fov_y_deg) = match parts[..] {
            [eye, target] => (point(eye)?, point(target)?, DEFAULT_FOV_Y_DEG),
            [eye, target, fov] => (point(eye)?, point(target)?, number(fov)?),
            _ => return Err(syntax()),
        };
        if !(fov_y_deg > 0.0 && fov_y_deg < 180.0) {
            return Err(CameraSpecError::FieldOfView(text.to_owned()));
        }
        if position.distance(target) < 1e-6 {
            return Err(CameraSpecError::Nowhere(text.to_owned()));
        }
        if (target - position).normalize().y.abs() > 0.9999 {
            return Err(CameraSpecError::Vertical(text.to_owned()));
        }
        Ok(CameraSpec { position, target, fov_y_deg })
    }

    /// The camera looking from `position` at `target`, its planes fitted to the box [lo, hi]
    /// as a scene file's are.
    pub fn camera(&self, (lo, hi): (Vec3, Vec3)) -> Camera {
        let (near, far) = clip_planes_for(lo, hi, self.position);
        Camera::looking_at(self.position, self.target, self.fov_y_deg, near, far)
    }

    /// `camera` in the form `parse` reads, its target `distance` ahead (the viewer's C key).
    pub fn describe(camera: &Camera, distance: f32) -> String {
        let (p, t) = (camera.position, camera.position + camera.forward() * distance);
        format!("{},{},{}:{},{},{}:{}", p.x, p.y, p.z, t.x, t.y, t.z, camera.fov_y_deg)
    }
}

/// The planes of `view_proj`'s frustum (Vulkan depth 0..1), each with its inside positive:
/// left, right, top, bottom, near, far.
pub fn frustum_planes(view_proj: Mat4) -> [Vec4; 6] {
    let r = |i| view_proj.row(i);
    let planes = [r(3) + r(0), r(3) - r(0), r(3) + r(1), r(3) - r(1), r(2), r(3) - r(2)];
    planes.map(|p| p / p.truncate().length())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn camera_specs_parse_and_bad_ones_say_why() {
        let c = CameraSpec::parse("1,2,3:0,0,0:45").unwrap();
        assert_eq!(c, CameraSpec { position: Vec3::new(1.0, 2.0, 3.0), target: Vec3::ZERO, fov_y_deg: 45.0 });
        assert_eq!(CameraSpec::parse(" -1.5, 2,3 :4,5,6").unwrap().fov_y_deg, DEFAULT_FOV_Y_DEG);
        for bad in ["", "1,2,3", "1,2:3,4,5", "1,2,3:4,5,6:7:8", "a,2,3:4,5,6", "1,2,3:4,5,nan", "1,2,3:4,5,inf"] {
            assert!(matches!(CameraSpec::parse(bad), Err(CameraSpecError::Syntax(_))), "{bad}");
        }
        assert!(matches!(CameraSpec::parse("1,2,3:0,0,0:180"), Err(CameraSpecError::FieldOfView(_))));
        assert!(matches!(CameraSpec::parse("1,2,3:0,0,0:0"), Err(CameraSpecError::FieldOfView(_))));
        assert!(matches!(CameraSpec::parse("1,2,3:1,2,3"), Err(CameraSpecError::Nowhere(_))));
        assert!(matches!(CameraSpec::parse("0,5,0:0,0,0"), Err(CameraSpecError::Vertical(_))));
    }

    #[test]
    fn clip_planes_hold_the_box_wherever_the_camera_stands() {
        let (lo, hi) = (Vec3::splat(-1.0), Vec3::splat(1.0));
        let r = 3f32.sqrt();
        let (near, far) = clip_planes_for(lo, hi, Vec3::new(0.0, 0.0, 10.0));
        assert!((near - (10.0 - r) * 0.5).abs() < 1e-5 && (far - (10.0 + 2.0 * r)).abs() < 1e-5);
        // Close by, even inside the box: a small near plane, never behind the eye.
        let (near, far) = clip_planes_for(lo, hi, Vec3::new(0.0, 0.0, 0.5));
        assert!(near > 0.0 && near < 1e-3 && far > 2.0 * r);
    }

    #[test]
    fn a_described_camera_parses_back_into_the_same_view() {
        let seed = Camera::seed();
        let spec = CameraSpec::parse(&CameraSpec::describe(&seed, 10.0)).unwrap();
        let back = spec.camera((Vec3::splat(-10.0), Vec3::splat(10.0)));
        assert!(back.position == seed.position && back.forward().abs_diff_eq(seed.forward(), 1e-5), "{back:?}");
        assert_eq!(back.fov_y_deg, seed.fov_y_deg);
    }

    #[test]
    fn projection_flips_y_and_maps_near_far_to_0_1() {
        let cam = Camera::looking_at(Vec3::ZERO, -Vec3::Z, 60.0, 0.1, 256.0);
        let vp = cam.projection(1.0) * cam.view();
        let clip = |p: Vec3| {
            let c = vp * p.extend(1.0);
            c.truncate() / c.w
        };
        assert!(clip(Vec3::new(0.0, 0.0, -0.1)).z.abs() < 1e-5);
        assert!((clip(Vec3::new(0.0, 0.0, -256.0)).z - 1.0).abs() < 1e-5);
        // +Y in the world is up, so it lands in the upper half: negative y in Vulkan NDC.
        assert!(clip(Vec3::new(0.0, 1.0, -5.0)).y < 0.0);
    }

    #[test]
    fn orthographic_projection_keeps_sizes_at_every_depth() {
        let cam = Camera { orthographic: Some(2.0), ..Camera::looking_at(Vec3::ZERO, -Vec3::Z, 60.0, 0.5, 50.0) };
        let vp = cam.projection(2.0) * cam.view();
        for depth in [0.5, 5.0, 50.0] {
            let c = vp * Vec3::new(4.0, 2.0, -depth).extend(1.0);
            assert!((c.w - 1.0).abs() < 1e-6);
            assert!((c.x - 1.0).abs() < 1e-5 && (c.y + 1.0).abs() < 1e-5, "{c}");
            assert!((c.z - (depth - 0.5) / 49.5).abs() < 1e-5);
        }
        // Every pixel's ray runs along the axis, from the near plane.
        let (o, d) = cam.pixel_ray(0, 0, 64, 32);
        assert!(d.abs_diff_eq(-Vec3::Z, 1e-5) && (o.z + 0.5).abs() < 1e-5 && o.x < -3.8 && o.y > 1.9, "{o} {d}");
        assert_eq!(cam.w_of_depth(), (0.0, 1.0));
    }

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
                        assert!((0.7..=FRAME_FILL + 1e-3).contains(&fill), "{what}: fills {fill}");
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

    #[test]
    fn pixel_rays_go_through_pixel_centres() {
        let cam = Camera::seed();
        let (o, d) = cam.pixel_ray(640, 360, 1281, 721);
        assert!((o - cam.position).length() < 0.2);
        assert!(d.dot(cam.forward()) > 0.99999);
        let (_, top) = cam.pixel_ray(640, 0, 1281, 721);
        assert!(top.y > d.y, "row 0 is the top of the image");
    }
}
