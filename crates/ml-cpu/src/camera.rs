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

#[cfg(test)]
mod tests {
    use super::*;

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
