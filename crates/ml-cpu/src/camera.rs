//! Camera (docs/DESIGN.md#conventions): right-handed, +Y up, view looks down −Z, Vulkan clip
//! space with Y flipped in the projection and depth 0..1; perspective, or orthographic (glTF).

use glam::{Mat4, Vec3, Vec4};

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

/// What a frame is seen through: a camera on an image of `width`×`height` pixels, with the
/// view and projection every pass of the frame takes (the frame's uniforms), the cluster grid
/// is cut along, and the transparent build bins by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    pub camera: Camera,
    pub width: u32,
    pub height: u32,
    /// World → view space (the eye at the origin, looking down −Z).
    pub view: Mat4,
    /// View → Vulkan clip space (`Camera::projection` at the image's aspect).
    pub projection: Mat4,
}

impl View {
    pub fn new(camera: Camera, width: u32, height: u32) -> View {
        View { camera, width, height, view: camera.view(), projection: camera.projection(width as f32 / height as f32) }
    }

    /// World → clip space.
    pub fn view_proj(&self) -> Mat4 {
        self.projection * self.view
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
    #[error("camera '{0}': the field of view must be at least {min} and below 180 degrees", min = crate::limits::MIN_FOV_Y_DEG)]
    FieldOfView(String),
    #[error("camera '{0}': a coordinate lies beyond ±{max}", max = crate::limits::MAX_COORDINATE)]
    TooFar(String),
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
        if !(crate::limits::MIN_FOV_Y_DEG..180.0).contains(&fov_y_deg) {
            return Err(CameraSpecError::FieldOfView(text.to_owned()));
        }
        if position.abs().max(target.abs()).max_element() > crate::limits::MAX_COORDINATE {
            return Err(CameraSpecError::TooFar(text.to_owned()));
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
        assert!(matches!(CameraSpec::parse("1,2,3:0,0,0:1e-30"), Err(CameraSpecError::FieldOfView(_))));
        assert!(matches!(CameraSpec::parse("1e30,2,3:0,0,0"), Err(CameraSpecError::TooFar(_))));
        assert!(matches!(CameraSpec::parse("1,2,3:0,-2e6,0"), Err(CameraSpecError::TooFar(_))));
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
