//! The seed's first-person camera: W/S forward and back, A/D sideways, Q/E down and up (world
//! axes for height), right-drag to look, the wheel to change speed.

use glam::Vec3;
use ml_cpu::camera::Camera;

/// Which movement keys are held.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct MoveKeys {
    pub forward: bool,
    pub back: bool,
    pub left: bool,
    pub right: bool,
    pub down: bool,
    pub up: bool,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FirstPerson {
    pub keys: MoveKeys,
    /// World units per second.
    pub speed: f32,
    /// Degrees of turn per pixel dragged.
    pub degrees_per_pixel: f32,
}

impl Default for FirstPerson {
    fn default() -> FirstPerson {
        FirstPerson { keys: MoveKeys::default(), speed: 5.0, degrees_per_pixel: 0.2 }
    }
}

/// Pitch stays short of straight up and down, where yaw is undefined.
const MAX_PITCH_DEG: f32 = 89.0;

impl FirstPerson {
    /// `camera` moved by the held keys over `seconds`.
    pub fn moved(&self, camera: Camera, seconds: f32) -> Camera {
        let k = self.keys;
        let axis = |plus: bool, minus: bool| f32::from(u8::from(plus)) - f32::from(u8::from(minus));
        let forward = camera.forward();
        let right = forward.cross(Vec3::Y).normalize_or_zero();
        let step = forward * axis(k.forward, k.back) + right * axis(k.right, k.left) + Vec3::Y * axis(k.up, k.down);
        Camera { position: camera.position + step.normalize_or_zero() * self.speed * seconds, ..camera }
    }

    /// `camera` turned by a mouse drag of (dx, dy) pixels (right and down positive).
    pub fn turned(&self, camera: Camera, (dx, dy): (f64, f64)) -> Camera {
        let yaw_deg = camera.yaw_deg + dx as f32 * self.degrees_per_pixel;
        let pitch_deg = (camera.pitch_deg - dy as f32 * self.degrees_per_pixel).clamp(-MAX_PITCH_DEG, MAX_PITCH_DEG);
        Camera { yaw_deg, pitch_deg, ..camera }
    }

    /// Wheel `lines` (up positive): each line 20 % faster or slower.
    pub fn scroll(&mut self, lines: f32) {
        self.speed = (self.speed * 1.2f32.powf(lines)).clamp(0.01, 10_000.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_move_along_the_view_and_the_world_up() {
        let camera = Camera::looking_at(Vec3::ZERO, Vec3::new(0.0, 0.0, -1.0), 60.0, 0.1, 100.0);
        let mut c = FirstPerson::default();
        c.keys.forward = true;
        assert!(c.moved(camera, 2.0).position.abs_diff_eq(Vec3::new(0.0, 0.0, -10.0), 1e-4));
        c.keys = MoveKeys { right: true, ..Default::default() };
        assert!(c.moved(camera, 1.0).position.abs_diff_eq(Vec3::new(5.0, 0.0, 0.0), 1e-4));
        c.keys = MoveKeys { up: true, ..Default::default() };
        assert!(c.moved(camera, 1.0).position.abs_diff_eq(Vec3::new(0.0, 5.0, 0.0), 1e-4));
        // Diagonals are not faster.
        c.keys = MoveKeys { forward: true, right: true, ..Default::default() };
        assert!((c.moved(camera, 1.0).position.length() - 5.0).abs() < 1e-4);
    }

    #[test]
    fn dragging_turns_and_pitch_stops_short_of_vertical() {
        let camera = Camera::looking_at(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), 60.0, 0.1, 100.0);
        let c = FirstPerson::default();
        let turned = c.turned(camera, (450.0, 0.0));
        assert!((turned.yaw_deg - 90.0).abs() < 1e-3 && turned.forward().abs_diff_eq(Vec3::Z, 1e-4));
        assert_eq!(c.turned(camera, (0.0, -10_000.0)).pitch_deg, MAX_PITCH_DEG);
        let mut fast = c;
        fast.scroll(2.0);
        assert!((fast.speed - 7.2).abs() < 1e-4);
    }
}
