//! Light layouts (the seed's grid, or seeded random places) and the seed's light animation.

use crate::gpu_types::PointLight;
use crate::SceneError;
use glam::Vec3;
use rand::{Rng, SeedableRng};
use std::f32::consts::TAU;

/// The most lights a scene may hold (16.7 M × 32 B = 512 MiB of light data). Above a million
/// is what the clustered techniques are built for; beyond this is a typo, not a workload.
pub const MAX_LIGHTS: u64 = 1 << 24;

/// The seed's light colours, cycled by index.
pub const SEED_COLORS: [[f32; 3]; 4] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]];

/// Half-size of the seed grid in x and z, and its height above the objects.
pub const GRID_HALF_SIZE: f32 = 15.0;
pub const GRID_HEIGHT: f32 = 7.5;
pub const SEED_RADIUS: f32 = 15.0;

/// The `random` layout's box: x,z ∈ [−20, 20], y ∈ [−2, 12].
pub const RANDOM_BOX_MIN: Vec3 = Vec3::new(-20.0, -2.0, -20.0);
pub const RANDOM_BOX_MAX: Vec3 = Vec3::new(20.0, 12.0, 20.0);

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightLayout {
    /// ceil(√N)² grid over x,z ∈ [−15, 15] at y = 7.5 (the seed's).
    Grid,
    /// Uniform in the random box, from a seed.
    Random,
}

impl LightLayout {
    pub const ALL: [LightLayout; 2] = [LightLayout::Grid, LightLayout::Random];

    pub fn name(self) -> &'static str {
        match self {
            LightLayout::Grid => "grid",
            LightLayout::Random => "random",
        }
    }

    pub fn from_name(name: &str) -> Result<LightLayout, SceneError> {
        crate::error::find_named("light layout", &LightLayout::ALL, LightLayout::name, name)
    }
}

/// Light radii: one value or a range sampled uniformly per light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadiusRange {
    pub min: f32,
    pub max: f32,
}

impl RadiusRange {
    pub const fn fixed(r: f32) -> RadiusRange {
        RadiusRange { min: r, max: r }
    }

    /// Parse `R` or `MIN..MAX`.
    pub fn parse(text: &str) -> Result<RadiusRange, SceneError> {
        let bad = || SceneError::LightRadius(text.to_owned());
        let num = |s: &str| s.trim().parse::<f32>().map_err(|_| bad());
        let range = match text.split_once("..") {
            Some((lo, hi)) => RadiusRange { min: num(lo)?, max: num(hi)? },
            None => RadiusRange::fixed(num(text)?),
        };
        let ok = range.min.is_finite() && range.max.is_finite() && range.min > 0.0 && range.min <= range.max;
        ok.then_some(range).ok_or_else(bad)
    }

    fn sample(&self, rng: &mut impl Rng) -> f32 {
        if self.min == self.max {
            self.min
        } else {
            rng.random_range(self.min..=self.max)
        }
    }
}

/// Everything that decides a scene's lights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightParams {
    pub count: u32,
    pub layout: LightLayout,
    pub seed: u64,
    pub radius: RadiusRange,
}

impl LightParams {
    pub fn seed_default() -> LightParams {
        LightParams { count: 64, layout: LightLayout::Grid, seed: 1, radius: RadiusRange::fixed(SEED_RADIUS) }
    }

    pub fn check_count(count: u64) -> Result<u32, SceneError> {
        if (1..=MAX_LIGHTS).contains(&count) {
            Ok(count as u32)
        } else {
            Err(SceneError::LightCount(count))
        }
    }

    /// The lights at rest (before animation).
    pub fn build(&self) -> Result<Vec<PointLight>, SceneError> {
        let n = Self::check_count(self.count as u64)? as usize;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.seed);
        let mut lights = Vec::with_capacity(n);
        let side = (n as f64).sqrt().ceil() as usize;
        for i in 0..n {
            let position = match self.layout {
                LightLayout::Grid => {
                    let step = if side > 1 { 2.0 * GRID_HALF_SIZE / (side - 1) as f32 } else { 0.0 };
                    let origin = if side > 1 { -GRID_HALF_SIZE } else { 0.0 };
                    Vec3::new(origin + (i % side) as f32 * step, GRID_HEIGHT, origin + (i / side) as f32 * step)
                }
                LightLayout::Random => Vec3::new(
                    rng.random_range(RANDOM_BOX_MIN.x..=RANDOM_BOX_MAX.x),
                    rng.random_range(RANDOM_BOX_MIN.y..=RANDOM_BOX_MAX.y),
                    rng.random_range(RANDOM_BOX_MIN.z..=RANDOM_BOX_MAX.z),
                ),
            };
            let radius = self.radius.sample(&mut rng);
            let c = SEED_COLORS[i % SEED_COLORS.len()];
            lights.push(PointLight { position_radius: [position.x, position.y, position.z, radius], color: [c[0], c[1], c[2], 0.0] });
        }
        Ok(lights)
    }
}

/// The seed's animation: every light moves by (sin 2πt, 0, cos 2πt) · 0.1 from its rest place.
pub fn animation_offset(t: f32) -> Vec3 {
    Vec3::new((TAU * t).sin() * 0.1, 0.0, (TAU * t).cos() * 0.1)
}

/// Write the lights at time t into `out` (same length as `rest`).
pub fn animate_into(rest: &[PointLight], t: f32, out: &mut [PointLight]) {
    let d = animation_offset(t);
    for (o, l) in out.iter_mut().zip(rest) {
        let p = l.position_radius;
        *o = PointLight { position_radius: [p[0] + d.x, p[1] + d.y, p[2] + d.z, p[3]], color: l.color };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn seed_grid_spans_the_square_and_cycles_colours() {
        let lights = LightParams::seed_default().build().unwrap();
        assert_eq!(lights.len(), 64);
        assert_eq!(lights[0].position_radius, [-15.0, 7.5, -15.0, 15.0]);
        assert_eq!(lights[63].position_radius, [15.0, 7.5, 15.0, 15.0]);
        assert_eq!(lights[5].color, [0.0, 1.0, 0.0, 0.0]);
        // 5 lights: a 3×3 grid, first five places.
        let five = LightParams { count: 5, ..LightParams::seed_default() }.build().unwrap();
        assert_eq!(five[4].position_radius[..3], [0.0, 7.5, 0.0]);
    }

    #[test]
    fn random_layout_is_seeded_in_the_box_with_radii_in_range() {
        let p = LightParams { count: 1000, layout: LightLayout::Random, seed: 7, radius: RadiusRange { min: 0.5, max: 4.0 } };
        let a = p.build().unwrap();
        assert_eq!(a, p.build().unwrap());
        assert_ne!(a, LightParams { seed: 8, ..p }.build().unwrap());
        for l in &a {
            let pos = Vec3::from_slice(&l.position_radius[..3]);
            assert!(pos.cmpge(RANDOM_BOX_MIN).all() && pos.cmple(RANDOM_BOX_MAX).all());
            assert!((0.5..=4.0).contains(&l.position_radius[3]));
        }
    }

    #[test]
    fn counts_and_radii_are_checked() {
        assert_eq!(LightParams::check_count(0), Err(SceneError::LightCount(0)));
        assert!(LightParams::check_count(100_000_000).is_err());
        assert_eq!(LightParams::check_count(1_000_000), Ok(1_000_000));
        assert_eq!(RadiusRange::parse("2.5"), Ok(RadiusRange::fixed(2.5)));
        assert_eq!(RadiusRange::parse("1..3"), Ok(RadiusRange { min: 1.0, max: 3.0 }));
        for bad in ["0", "-1", "3..1", "nan", "x", "1..", "inf"] {
            assert!(RadiusRange::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn animation_moves_every_light_by_the_same_small_circle() {
        let rest = LightParams::seed_default().build().unwrap();
        let mut out = rest.clone();
        animate_into(&rest, 0.25, &mut out);
        assert!((out[0].position_radius[0] - (-15.0 + 0.1)).abs() < 1e-6);
        assert!((out[0].position_radius[2] - -15.0).abs() < 1e-6);
        animate_into(&rest, 0.0, &mut out);
        assert!((out[9].position_radius[2] - (rest[9].position_radius[2] + 0.1)).abs() < 1e-6);
    }
}
