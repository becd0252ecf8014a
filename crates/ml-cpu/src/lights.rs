//! Light layouts (a grid above the scene like the seed's — in a fitted frame a lattice of such
//! grids stacked down through the scene's box once the count calls for it —, seeded random
//! places in the scene's box, or points just above its surfaces), the frame they are placed in
//! (the built-in scenes' fixed one, or one fitted to a scene's box), the default radius that
//! fits a count to a frame, and the seed's light animation.

use crate::gpu_types::PointLight;
use crate::limits::{LENGTHS, MAX_LIGHTS};
use crate::surface_sampler::SurfaceSampler;
use crate::SceneError;
use glam::{Vec2, Vec3};
use rand::{Rng, SeedableRng};
use std::f32::consts::TAU;

/// The seed's light colours, cycled by index.
pub const SEED_COLORS: [[f32; 3]; 4] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 1.0, 0.0]];

/// The near-white colours of a file's default lights, cycled by index: warm, neutral and
/// cool whites (a little variety, no tint: their mean is grey), so that a model shows its
/// materials' own colours.
pub const WHITE_COLORS: [[f32; 3]; 3] = [[1.0, 0.93, 0.85], [0.96, 0.96, 0.96], [0.88, 0.94, 1.0]];

/// What colours placed lights get.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightColors {
    /// The seed's saturated red, green, blue and yellow (`SEED_COLORS`): the seed scene's.
    Palette,
    /// Near-white (`WHITE_COLORS`): scene and glTF files' default, which shows materials.
    White,
}

impl LightColors {
    pub const ALL: [LightColors; 2] = [LightColors::Palette, LightColors::White];

    pub fn name(self) -> &'static str {
        match self {
            LightColors::Palette => "palette",
            LightColors::White => "white",
        }
    }

    pub fn from_name(name: &str) -> Result<LightColors, SceneError> {
        crate::error::find_named("light colours", &LightColors::ALL, LightColors::name, name)
    }

    /// Light `i`'s colour.
    pub fn color(self, i: usize) -> [f32; 3] {
        match self {
            LightColors::Palette => SEED_COLORS[i % SEED_COLORS.len()],
            LightColors::White => WHITE_COLORS[i % WHITE_COLORS.len()],
        }
    }

    /// `lights` coloured so, by index (their own strength kept: each colour's largest
    /// channel is 1, as the palette's are).
    pub fn paint(self, lights: &mut [PointLight]) {
        for (i, l) in lights.iter_mut().enumerate() {
            let c = self.color(i);
            l.color = [c[0], c[1], c[2], l.color[3]];
        }
    }
}

/// Half-size of the seed grid in x and z, and its height above the objects.
pub const GRID_HALF_SIZE: f32 = 15.0;
pub const GRID_HEIGHT: f32 = 7.5;
pub const SEED_RADIUS: f32 = 15.0;

/// The `random` layout's box: x,z ∈ [−20, 20], y ∈ [−2, 12].
pub const RANDOM_BOX_MIN: Vec3 = Vec3::new(-20.0, -2.0, -20.0);
pub const RANDOM_BOX_MAX: Vec3 = Vec3::new(20.0, 12.0, 20.0);

/// Lights whose spheres reach an average point of the scene under a fitted default radius
/// (`LightFrame::default_radius`); the bench scene keeps the same number at every count.
pub const LIGHTS_PER_POINT: f32 = 4.0;

/// Lights of the default rig that a scene file or glTF file without any light gets: the seed
/// scene's 64, on a grid fitted to the scene's box.
pub const DEFAULT_RIG_LIGHTS: u32 = 64;

/// The seed scene's own light count: up to it, its lights keep the seed's radius.
pub const SEED_LIGHT_COUNT: u32 = 64;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightLayout {
    /// ceil(√N)² grid over the frame's square (the seed's: x,z ∈ [−15, 15] at y = 7.5); in a
    /// fitted frame, layers of such grids from that height down to the frame's floor, as many
    /// as keep the lattice's steps about equal (`GridShape`).
    Grid,
    /// Uniform in the frame's box, from a seed.
    Random,
    /// Just above seeded random points of the scene's surfaces, area-weighted.
    Surface,
}

impl LightLayout {
    pub const ALL: [LightLayout; 3] = [LightLayout::Grid, LightLayout::Random, LightLayout::Surface];

    pub fn name(self) -> &'static str {
        match self {
            LightLayout::Grid => "grid",
            LightLayout::Random => "random",
            LightLayout::Surface => "surface",
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

/// Where the layouts put lights: the grid's square (centre at its height, half-size in x and z)
/// with the floor its layers may reach down to, and the random layout's box. The built-in
/// scenes have a fixed one (their images never change); a scene file or glTF file gets one
/// fitted to its box, so that lights scale with the model.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightFrame {
    pub grid_centre: Vec3,
    pub grid_half_size: f32,
    /// The height of the lowest layer a grid may have: the built-in frame's is the grid's own
    /// (one plane at every count), a fitted frame's the bottom of its box.
    pub grid_floor: f32,
    pub box_min: Vec3,
    pub box_max: Vec3,
    /// Whether grid lights are moved off their places at random within their cells (a fitted
    /// frame's: a regular lattice of many lights prints a pattern of dots or stripes on every
    /// surface; the built-in frame keeps the seed's exact grid).
    pub jittered: bool,
}

/// How a grid of some count is laid out: `layers` layers (the first at the grid's height, the
/// last at its floor) of `side`² places each, filled in order (the last layer may be part
/// full), `step` apart in x and z and `rise` apart in height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GridShape {
    pub side: usize,
    pub layers: usize,
    pub step: f32,
    pub rise: f32,
}

/// How far a fitted grid rises above the scene's top, as a fraction of its largest side (the
/// seed's grid is 6.5 m above spheres spread over 17 m: 0.38; lower keeps more of a small
/// count's light on the scene).
const GRID_RISE: f32 = 0.25;
/// The fitted grid's half-size over the scene's half-footprint: a little wider than the scene,
/// so that its edges are lit from outside as well as its middle.
const GRID_OVERHANG: f32 = 1.1;
/// The least radius of a fitted grid's lights over their height above the scene's middle:
/// many lights high over a flat scene would otherwise reach it only at the very end of their
/// radius, where the falloff is near zero; with this a light straight above the middle gives
/// it at least (1 − 1/1.25)² = 0.04.
const GRID_REACH: f32 = 1.25;
/// The least radius of a layered grid's lights over half the diagonal of a lattice cell (the
/// furthest a point among the lights is from the nearest): every such point then has a light
/// within 3/4 of its radius, which gives it at least (1 − 3/4)² = 1/16. In a cubic lattice this
/// decides, and brings about 6.5 lights to a point.
const LATTICE_REACH: f32 = 4.0 / 3.0;
/// How far a fitted random box reaches past the scene's box on every side, as a fraction of
/// its largest side: inside the scene's own box a closed model (a cube) would hold every
/// light inside itself, lighting only its inner faces.
const BOX_MARGIN: f32 = 0.25;
/// The thinnest side of a fitted box, as a fraction of its largest: a flat model (a plane)
/// still gets a volume to place lights in.
const MIN_BOX_SIDE: f32 = 0.25;

impl LightFrame {
    /// The built-in scenes' frame: the grid over x,z ∈ [−15, 15] at y = 7.5, the box
    /// x,z ∈ [−20, 20], y ∈ [−2, 12].
    pub const BUILT_IN: LightFrame = LightFrame {
        grid_centre: Vec3::new(0.0, GRID_HEIGHT, 0.0),
        grid_half_size: GRID_HALF_SIZE,
        grid_floor: GRID_HEIGHT,
        box_min: RANDOM_BOX_MIN,
        box_max: RANDOM_BOX_MAX,
        jittered: false,
    };

    /// The seed scene's frame for `count` lights: the built-in one up to the seed's 64 (its
    /// grid one plane, its radius the seed's 15); beyond, its grid stacks layers down to the
    /// objects' middle plane (y = 0), so that the default radius can shrink as the count grows
    /// and every point keeps a few lights (one plane of many lights would need a radius that
    /// reaches the objects 7.5 below from every light: thousands of lights a point).
    pub fn seed(count: u32) -> LightFrame {
        if count <= SEED_LIGHT_COUNT {
            LightFrame::BUILT_IN
        } else {
            LightFrame { grid_floor: 0.0, ..LightFrame::BUILT_IN }
        }
    }

    /// The frame fitted to a scene's box [lo, hi]: the grid a little wider than the scene's
    /// footprint, GRID_RISE of the largest side above its top, its floor the bottom of the
    /// box; the box is the scene's own, each side at least MIN_BOX_SIDE of the largest, grown
    /// by BOX_MARGIN of the largest on every side. Scaling the scene scales the frame.
    pub fn around(lo: Vec3, hi: Vec3) -> LightFrame {
        let centre = (lo + hi) * 0.5;
        let largest = (hi - lo).max_element().max(f32::MIN_POSITIVE);
        let half = ((hi - lo) * 0.5).max(Vec3::splat(largest * MIN_BOX_SIDE * 0.5)) + largest * BOX_MARGIN;
        let footprint = Vec2::new(hi.x - lo.x, hi.z - lo.z).max_element() * 0.5;
        LightFrame {
            grid_centre: Vec3::new(centre.x, hi.y + GRID_RISE * largest, centre.z),
            grid_half_size: (footprint * GRID_OVERHANG).max(largest * MIN_BOX_SIDE * 0.5),
            grid_floor: (centre - half).y,
            box_min: centre - half,
            box_max: centre + half,
            jittered: true,
        }
    }

    /// How far its lights move in the animation: the seed's 0.1 in the built-in frame, and
    /// as much of a fitted frame as that is of the built-in one (its box's largest side), so
    /// that the motion scales with the model as the lights do.
    pub fn motion(&self) -> f32 {
        let side = |f: &LightFrame| (f.box_max - f.box_min).max_element();
        SEED_MOTION * side(self) / side(&LightFrame::BUILT_IN)
    }

    /// How `count` grid lights are laid out. One plane of ⌈√N⌉² (the seed's grid) while the
    /// lattice's steps would be over twice the height from the grid to its floor; more lights
    /// stack layers down to the floor, about as far apart as the places in a layer: L layers
    /// where a cubic lattice of N lights through the grid's volume V = A·H would have steps
    /// s = ∛(V/N), L ≈ 1 + H/s, each layer ⌈√⌈N/L⌉⌉² places (so L grows as ∛N, and every
    /// point of the scene keeps near lights at any count). The built-in frame has no height
    /// to fill (its floor is the grid's height): one plane always.
    pub fn grid_shape(&self, count: u32) -> GridShape {
        let n = count.max(1) as usize;
        let width = 2.0 * self.grid_half_size;
        let height = (self.grid_centre.y - self.grid_floor).max(0.0);
        let wanted = if height > 0.0 {
            let s = (width * width * height / n as f32).cbrt();
            // (At least 1 also where a box without end makes this NaN.)
            ((1.0 + (height / s).round()).clamp(1.0, n as f32) as usize).max(1)
        } else {
            1
        };
        let side = ((n.div_ceil(wanted)) as f64).sqrt().ceil() as usize;
        let layers = n.div_ceil(side * side);
        let step = if side > 1 { width / (side - 1) as f32 } else { 0.0 };
        let rise = if layers > 1 { height / (layers - 1) as f32 } else { 0.0 };
        GridShape { side, layers, step, rise }
    }

    /// The radius at which `count` lights of `layout` reach about LIGHTS_PER_POINT lights at a
    /// point of the scene (as the bench scene's do at every count):
    /// - random, uniform in the box of volume V: count · (4/3)πr³ / V = k;
    /// - grid of one plane, n lights over the square of area A at height h above the box's
    ///   centre: a point there is reached by the lights within √(r² − h²) in the plane,
    ///   n·π(r² − h²) / A = k (and r at least GRID_REACH·h);
    /// - grid of layers (`grid_shape`), each light alone in a cell of volume step²·rise:
    ///   (4/3)πr³ / cell = k, and r at least LATTICE_REACH times half the cell's diagonal, so
    ///   that every point among the lights has one within 3/4 of its radius (a cubic lattice
    ///   then brings about 6.5 lights to a point, whatever the count);
    /// - surface, n lights just above surfaces of area S: a point is reached by those within r
    ///   along the surface, n·πr² / S = k.
    ///
    /// Every term scales with the scene, so the lit image does not change with its size.
    pub fn default_radius(&self, layout: LightLayout, count: u32, surface_area: f32) -> f32 {
        let (n, k, pi) = (count.max(1) as f32, LIGHTS_PER_POINT, std::f32::consts::PI);
        match layout {
            LightLayout::Random => (k * (self.box_max - self.box_min).element_product() / (n * 4.0 / 3.0 * pi)).cbrt(),
            LightLayout::Grid => {
                let shape = self.grid_shape(count);
                if shape.layers == 1 {
                    let area = (2.0 * self.grid_half_size).powi(2);
                    let h = self.grid_centre.y - (self.box_min.y + self.box_max.y) * 0.5;
                    (h * h + k * area / (n * pi)).sqrt().max(GRID_REACH * h)
                } else {
                    // One light a layer (a tiny count over a tall frame): the layer's square is its cell.
                    let step = if shape.side > 1 { shape.step } else { 2.0 * self.grid_half_size };
                    let cell = step * step * shape.rise;
                    let half_diagonal = 0.5 * (2.0 * step * step + shape.rise * shape.rise).sqrt();
                    (3.0 * k * cell / (4.0 * pi)).cbrt().max(LATTICE_REACH * half_diagonal)
                }
            }
            LightLayout::Surface => (k * surface_area / (n * pi)).sqrt(),
        }
    }
}

impl LightFrame {
    /// `default_radius`, refused where no light can have it: a box of no size (or none at all)
    /// fits lights of radius 0 (or inf), which light nothing (or overflow the light lists).
    /// The loaders refuse such boxes first (`scene_load::check_extent`); this is the last word.
    pub fn fitted_radius(&self, layout: LightLayout, count: u32, surface_area: f32) -> Result<f32, SceneError> {
        let radius = self.default_radius(layout, count, surface_area);
        if LENGTHS.contains(&radius) {
            Ok(radius)
        } else {
            Err(SceneError::FittedRadius(radius))
        }
    }
}

/// How far the surface layout lifts a light off its surface, as a fraction of its radius:
/// enough that the point under it is not lit at a grazing distance of zero, little enough
/// that the light stays on its side of thin geometry.
pub const SURFACE_LIFT: f32 = 0.05;

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
        LightParams { count: SEED_LIGHT_COUNT, layout: LightLayout::Grid, seed: 1, radius: RadiusRange::fixed(SEED_RADIUS) }
    }

    pub fn check_count(count: u64) -> Result<u32, SceneError> {
        if (1..=MAX_LIGHTS).contains(&count) {
            Ok(count as u32)
        } else {
            Err(SceneError::LightCount(count))
        }
    }

    /// The lights at rest (before animation) in the built-in scenes' frame; the surface
    /// layout needs a scene's surfaces (`build_in`, `Scene::build_lights`).
    pub fn build(&self) -> Result<Vec<PointLight>, SceneError> {
        self.build_in(&LightFrame::BUILT_IN, None)
    }

    /// The lights at rest in `frame`; `surfaces` (the scene's, for the surface layout) lifts
    /// each light SURFACE_LIFT of its radius off a point drawn from them.
    pub fn build_in(&self, frame: &LightFrame, surfaces: Option<&SurfaceSampler>) -> Result<Vec<PointLight>, SceneError> {
        let n = Self::check_count(self.count as u64)? as usize;
        let surfaces = match (self.layout, surfaces) {
            (LightLayout::Surface, None) => return Err(SceneError::NoSurface),
            (_, surfaces) => surfaces,
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(self.seed);
        // The grid's jitter draws from its own sequence: the radii stay those of the exact grid.
        let mut jitter = rand_chacha::ChaCha8Rng::seed_from_u64(self.seed ^ 0x6a17);
        let mut lights = Vec::with_capacity(n);
        let grid = frame.grid_shape(self.count);
        let (lo, hi, half) = (frame.box_min, frame.box_max, frame.grid_half_size);
        for i in 0..n {
            // Where the light goes, and the direction it is lifted along by a part of its radius
            // (a surface's normal; zero for the other layouts).
            let (at, lift) = match (self.layout, surfaces) {
                (LightLayout::Grid, _) => {
                    let GridShape { side, step, rise, .. } = grid;
                    let origin = if side > 1 { -half } else { 0.0 };
                    let (layer, place) = (i / (side * side), i % (side * side));
                    let offset =
                        Vec3::new(origin + (place % side) as f32 * step, -(layer as f32) * rise, origin + (place / side) as f32 * step);
                    // Anywhere in the light's cell (half a step each way; layers half a rise,
                    // not above the grid nor below its floor).
                    let moved = if frame.jittered {
                        let mut within = |extent: f32| if extent > 0.0 { jitter.random_range(-0.5..0.5) * extent } else { 0.0 };
                        let (x, z, y) = (within(step), within(step), within(rise));
                        let y = if layer == 0 {
                            -y.abs()
                        } else if layer + 1 == grid.layers {
                            y.abs()
                        } else {
                            y
                        };
                        Vec3::new(x, y, z)
                    } else {
                        Vec3::ZERO
                    };
                    (frame.grid_centre + offset + moved, Vec3::ZERO)
                }
                (LightLayout::Surface, Some(surfaces)) => surfaces.sample(&mut rng),
                _ => (Vec3::new(rng.random_range(lo.x..=hi.x), rng.random_range(lo.y..=hi.y), rng.random_range(lo.z..=hi.z)), Vec3::ZERO),
            };
            let radius = self.radius.sample(&mut rng);
            let position = at + lift * (radius * SURFACE_LIFT);
            let c = SEED_COLORS[i % SEED_COLORS.len()];
            lights.push(PointLight { position_radius: [position.x, position.y, position.z, radius], color: [c[0], c[1], c[2], 0.0] });
        }
        Ok(lights)
    }
}

/// How far the seed's lights move in its animation.
pub const SEED_MOTION: f32 = 0.1;

/// The seed's animation: every light moves by (sin 2πt, 0, cos 2πt) · 0.1 from its rest place.
pub fn animation_offset(t: f32) -> Vec3 {
    motion_offset(t, SEED_MOTION)
}

/// The seed's animation with another amplitude (lights fitted to a scene move by as much of
/// their frame as the seed's move of theirs: `LightFrame::motion`).
pub fn motion_offset(t: f32, amplitude: f32) -> Vec3 {
    Vec3::new((TAU * t).sin() * amplitude, 0.0, (TAU * t).cos() * amplitude)
}

/// Write the lights at time t of the seed's animation into `out` (same length as `rest`).
pub fn animate_into(rest: &[PointLight], t: f32, out: &mut [PointLight]) {
    move_into(rest, animation_offset(t), out);
}

/// Write the lights moved by `d` into `out` (same length as `rest`).
pub fn move_into(rest: &[PointLight], d: Vec3, out: &mut [PointLight]) {
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
    fn the_built_in_frame_is_the_seed_grid_and_the_random_box() {
        assert_eq!(LightFrame::BUILT_IN.grid_centre, Vec3::new(0.0, GRID_HEIGHT, 0.0));
        assert_eq!((LightFrame::BUILT_IN.box_min, LightFrame::BUILT_IN.box_max), (RANDOM_BOX_MIN, RANDOM_BOX_MAX));
        let grid = LightParams::seed_default();
        assert_eq!(grid.build().unwrap(), grid.build_in(&LightFrame::BUILT_IN, None).unwrap());
        assert_eq!(LightParams { layout: LightLayout::Surface, ..grid }.build(), Err(SceneError::NoSurface));
    }

    /// A scene's box scaled by s (about a point off the origin): every layout's lights scale
    /// with it, and so does the default radius, for every layout.
    #[test]
    fn fitted_frames_and_radii_scale_with_the_scene() {
        let (lo, hi) = (Vec3::new(-1.0, 0.0, -2.0), Vec3::new(3.0, 1.0, 2.0));
        let base = LightFrame::around(lo, hi);
        for s in [0.01f32, 100.0] {
            let frame = LightFrame::around(lo * s, hi * s);
            for layout in [LightLayout::Grid, LightLayout::Random] {
                let r = base.default_radius(layout, 256, 0.0);
                let rs = frame.default_radius(layout, 256, 0.0);
                assert!((rs / (r * s) - 1.0).abs() < 1e-4, "{layout:?} × {s}: {rs} against {r}");
                let p = LightParams { count: 256, layout, seed: 4, radius: RadiusRange::fixed(r) };
                let a = p.build_in(&base, None).unwrap();
                let b = LightParams { radius: RadiusRange::fixed(rs), ..p }.build_in(&frame, None).unwrap();
                for (a, b) in a.iter().zip(&b) {
                    let (pa, pb) = (Vec3::from_slice(&a.position_radius[..3]), Vec3::from_slice(&b.position_radius[..3]));
                    assert!(pb.abs_diff_eq(pa * s, 1e-3 * s.max(1.0) * 10.0), "{layout:?} × {s}: {pb} against {}", pa * s);
                }
            }
            let r = base.default_radius(LightLayout::Surface, 256, 30.0);
            assert!((frame.default_radius(LightLayout::Surface, 256, 30.0 * s * s) / (r * s) - 1.0).abs() < 1e-4);
        }
        // The grid hangs over the scene, the box holds it; a flat scene's box still has depth.
        assert!(base.grid_centre.y > hi.y && base.grid_half_size >= 2.0);
        let flat = LightFrame::around(Vec3::new(-1.0, 0.0, -1.0), Vec3::new(1.0, 0.0, 1.0));
        assert!((flat.box_max.y - flat.box_min.y - 1.5).abs() < 1e-6, "a quarter of 2 thick, and half of 2 of margin");
        assert!(flat.box_min.x == -1.5 && flat.box_max.z == 1.5);
    }

    /// Monte Carlo: points of the scene's box (random), of its middle plane (grid) or of its
    /// surface (surface) are reached by about LIGHTS_PER_POINT lights under the default radius.
    #[test]
    fn the_default_radius_brings_about_k_lights_to_a_point() {
        use crate::camera::Camera;
        use crate::material::Material;
        use crate::mesh::MeshKind;
        use crate::scene::{Object, Scene};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        // A floor of 20 × 20 m under the box (−10, 0, −10)..(10, 4, 10).
        let floor = Object::placed(MeshKind::Plane, Vec3::ZERO, 10.0, Material::named("white").unwrap());
        let scene = Scene::new(vec![floor], Vec::new(), Camera::seed());
        let surfaces = scene.surfaces().unwrap();
        let frame = LightFrame::around(Vec3::new(-10.0, 0.0, -10.0), Vec3::new(10.0, 4.0, 10.0));
        // The grid: checked below (with more than a few dozen lights GRID_REACH decides).
        for layout in [LightLayout::Random, LightLayout::Surface] {
            let count = 4096;
            let radius = frame.default_radius(layout, count, surfaces.area());
            let lights =
                LightParams { count, layout, seed: 2, radius: RadiusRange::fixed(radius) }.build_in(&frame, Some(&surfaces)).unwrap();
            let mut reached = 0;
            let samples = 300;
            for _ in 0..samples {
                // Away from the edges, where fewer lights are around.
                let inner = |a: f32, b: f32, rng: &mut rand_chacha::ChaCha8Rng| rng.random_range(a * 0.6..b * 0.6);
                let p = match layout {
                    LightLayout::Random => {
                        Vec3::new(inner(-10.0, 10.0, &mut rng), inner(0.0, 4.0, &mut rng) + 0.8, inner(-10.0, 10.0, &mut rng))
                    }
                    _ => Vec3::new(inner(-10.0, 10.0, &mut rng), 0.0, inner(-10.0, 10.0, &mut rng)),
                };
                reached += lights.iter().filter(|l| Vec3::from_slice(&l.position_radius[..3]).distance(p) < l.position_radius[3]).count();
            }
            let mean = reached as f32 / samples as f32;
            assert!((mean - LIGHTS_PER_POINT).abs() < 1.0, "{layout:?}: {mean} lights reach a point (radius {radius})");
        }
        // A few lights high over the scene: one plane, k of them reach the middle before
        // GRID_REACH takes over.
        let h = frame.grid_centre.y - 2.0;
        assert_eq!(frame.grid_shape(4).layers, 1);
        let few = frame.default_radius(LightLayout::Grid, 4, 0.0);
        assert!(few > GRID_REACH * h && ((few * few - h * h) * std::f32::consts::PI * 4.0 / (22.0 * 22.0) - LIGHTS_PER_POINT).abs() < 1e-3);
    }

    /// Lights of `layout` (default radius) within reach of each of `points`, on average.
    fn lights_reaching(lights: &[PointLight], points: &[Vec3]) -> f32 {
        let mut reached = 0usize;
        for p in points {
            for l in lights {
                let [x, y, z, r] = l.position_radius;
                let (dx, dy, dz) = (x - p.x, y - p.y, z - p.z);
                reached += (dx * dx + dy * dy + dz * dz < r * r) as usize;
            }
        }
        reached as f32 / points.len() as f32
    }

    /// Every layout under its default radius brings about the same number of lights to a
    /// point of the scene at every count, from the default rig's 64 to a million: random and
    /// surface about LIGHTS_PER_POINT, the grid (one plane for few lights, layers through the
    /// box for more) a few more. The cost of the clustered techniques follows these numbers.
    #[test]
    fn lights_reaching_a_point_stay_about_constant_at_every_count() {
        use crate::camera::Camera;
        use crate::material::Material;
        use crate::mesh::MeshKind;
        use crate::scene::{Object, Scene};
        // A cube of 2 m (its top and sides are surfaces) on a floor of 8 × 8 m.
        let objects = vec![
            Object::placed(MeshKind::Plane, Vec3::ZERO, 4.0, Material::named("white").unwrap()),
            Object::placed(MeshKind::Cube, Vec3::new(0.0, 1.0, 0.0), 1.0, Material::named("white").unwrap()),
        ];
        let scene = Scene::new(objects, Vec::new(), Camera::seed());
        let (lo, hi) = scene.bounds();
        let frame = LightFrame::around(lo, hi);
        let surfaces = scene.surfaces().unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        // Points of the model: in the inner part of its box (random, grid), on its surfaces (surface).
        let inner: Vec<Vec3> = (0..48)
            .map(|_| {
                let t = Vec3::new(rng.random_range(0.2..0.8), rng.random_range(0.2..0.8), rng.random_range(0.2..0.8));
                lo + (hi - lo) * t
            })
            .collect();
        let on_surface: Vec<Vec3> = (0..48).map(|_| surfaces.sample(&mut rng).0).filter(|p| p.x.abs() < 3.0 && p.z.abs() < 3.0).collect();
        for layout in LightLayout::ALL {
            let points = if layout == LightLayout::Surface { &on_surface } else { &inner };
            let mut seen = Vec::new();
            for count in [64u32, 256, 4096, 65536, 1 << 20] {
                let radius = frame.default_radius(layout, count, surfaces.area());
                let params = LightParams { count, layout, seed: 3, radius: RadiusRange::fixed(radius) };
                let lights = params.build_in(&frame, Some(&surfaces)).unwrap();
                let mean = lights_reaching(&lights, points);
                println!("{layout:?} × {count}: {mean:.2} lights reach a point (radius {radius:.4})");
                seen.push(mean);
            }
            let (least, most) = seen.iter().fold((f32::MAX, 0.0f32), |(a, b), &m| (a.min(m), b.max(m)));
            assert!(least >= 2.0 && most <= 12.0 && most <= least * 2.0, "{layout:?}: {seen:?} lights reach a point");
        }
    }

    /// A box of no size, or of infinite size, fits no radius: an error, not lights of radius 0
    /// or inf.
    #[test]
    fn degenerate_boxes_fit_no_radius() {
        let point = LightFrame::around(Vec3::ONE, Vec3::ONE);
        let endless = LightFrame::around(Vec3::splat(f32::MIN), Vec3::splat(f32::MAX));
        for layout in [LightLayout::Grid, LightLayout::Random] {
            for frame in [&point, &endless] {
                let e = frame.fitted_radius(layout, 64, 0.0).unwrap_err();
                assert!(e.to_string().starts_with("the lights fitted to the scene's box would get radius"), "{e}");
            }
        }
        assert_eq!(point.fitted_radius(LightLayout::Surface, 64, 0.0), Err(SceneError::FittedRadius(0.0)));
        let unit = LightFrame::around(Vec3::splat(-1.0), Vec3::ONE);
        assert_eq!(unit.fitted_radius(LightLayout::Grid, 64, 0.0), Ok(unit.default_radius(LightLayout::Grid, 64, 0.0)));
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
