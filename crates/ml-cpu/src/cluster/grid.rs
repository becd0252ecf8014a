//! The cluster grid: which cluster a fragment belongs to, and each cluster's view-space
//! bounding box.
//!
//! Tiles: a fragment at pixel (px, py) (row 0 at the top) is in tile
//! (px·X / width, py·Y / height) in integer arithmetic, exactly as the shader computes it.
//! Slices: slice = ⌊ln(z/near) / ln(far/near) · Z⌋ for view depth z (distance along −Z), written
//! as ⌊ln(z)·scale + bias⌋ with scale and bias computed here in f32 and handed to the shader,
//! so both sides evaluate the same expression (keep in sync with
//! `shaders/clusters/cluster.glsl`). The seed took the slice from NDC z as if it were linear
//! (mistake 2): NDC z of a perspective projection crowds almost every depth into the last few
//! slices.

use crate::camera::View;
use crate::limits::MAX_CLUSTERS;
use glam::{Mat4, Vec3, Vec3A};

/// Grid size X×Y×Z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct ClusterDims {
    pub x: u32,
    pub y: u32,
    pub z: u32,
}

impl ClusterDims {
    /// The default: 16×9 tiles (16:9 screens get square-ish tiles), 24 slices.
    pub const DEFAULT: ClusterDims = ClusterDims { x: 16, y: 9, z: 24 };

    /// Parse `XxYxZ`, e.g. `16x9x24`.
    pub fn parse(text: &str) -> Result<ClusterDims, crate::SceneError> {
        let bad = || crate::SceneError::Clusters(text.to_owned());
        let parts: Vec<u32> = text.split('x').map(|p| p.trim().parse::<u32>().map_err(|_| bad())).collect::<Result<_, _>>()?;
        let [x, y, z] = parts[..] else { return Err(bad()) };
        let total = x as u64 * y as u64 * z as u64;
        if x == 0 || y == 0 || z == 0 || total > MAX_CLUSTERS {
            return Err(bad());
        }
        Ok(ClusterDims { x, y, z })
    }

    pub fn count(&self) -> usize {
        (self.x * self.y * self.z) as usize
    }

    /// The grid `--clusters auto` takes for `lights` lights at `width`×`height`: the default
    /// scaled by s = 2^round(log₂ ∛(lights / 4096)), 1 ≤ s ≤ 4, on every axis. Where lights
    /// keep a constant density on screen as their count grows (the bench scene's radius
    /// ∝ N^(−1/3)), clusters as many times smaller keep the lights per cluster — the work per
    /// pixel — near constant: on the H100 at 1080p and 1M lights, 64×36×96 clusters held 14.5
    /// lights each instead of 414 and cut deferred-compute's lighting from 10.65 to 0.48 ms
    /// (docs/BENCHMARKS.md). s stops at 4 (221,184 clusters): beyond it the CPU assignment's
    /// time, not the shading, grows. Scaling up never makes tiles under 16 pixels.
    pub fn for_lights(lights: usize, width: u32, height: u32) -> ClusterDims {
        let scale = 2f64.powf((lights.max(1) as f64 / 4096.0).cbrt().log2().round()).clamp(1.0, 4.0) as u32;
        let d = Self::DEFAULT;
        ClusterDims { x: (d.x * scale).min((width / 16).max(d.x)), y: (d.y * scale).min((height / 16).max(d.y)), z: d.z * scale }
    }
}

/// Axis-aligned box in view space (16-byte lanes: the test below is a few SIMD operations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Aabb {
    /// Squared distance from `p` to the box (0 inside).
    pub fn distance_squared(&self, p: Vec3A) -> f32 {
        let d = (self.min - p).max(p - self.max).max(Vec3A::ZERO);
        d.length_squared()
    }
}

/// max and min without f32::max's NaN rules, which cost a compare and a blend per call on
/// x86 (~10 % of the assignment): one `maxss`/`minss` each. Inputs are never NaN here.
#[inline]
pub(super) fn max(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline]
pub(super) fn min(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// NDC range of scale·v/w over v ∈ [va, vb], w ∈ [w0, w1] with w > 0 (given as 1/w0, 1/w1;
/// w is the clip w: the depth for a perspective, 1 for an orthographic projection): the
/// extremes are at the corners, and v/w is monotonic in each.
/// With va ≤ vb the least v/w is at va and the greatest at vb (either w).
#[inline]
fn projected_span(scale: f32, va: f32, vb: f32, (inv0, inv1): (f32, f32)) -> (f32, f32) {
    let (lo, hi) = (min(va * inv0, va * inv1), max(vb * inv0, vb * inv1));
    if scale >= 0.0 {
        (lo * scale, hi * scale)
    } else {
        (hi * scale, lo * scale)
    }
}

/// Pixels whose centres may lie in NDC [lo, hi] (one pixel of margin), clamped to the image;
/// None when the span is off screen.
#[inline]
fn pixel_span(lo: f32, hi: f32, size: u32) -> Option<(u32, u32)> {
    let to_px = |ndc: f32| (ndc + 1.0) * 0.5 * size as f32;
    let (a, b) = (to_px(lo) - 1.0, to_px(hi) + 1.0);
    if b < 0.0 || a >= size as f32 {
        return None;
    }
    Some((max(a, 0.0) as u32, min(b, size as f32 - 1.0) as u32))
}

/// Tile of pixel `p` along an axis of `size` pixels split into `tiles`: ⌊p·tiles/size⌋, in
/// integer arithmetic as in the shader.
fn tile_of(p: u32, tiles: u32, size: u32) -> u32 {
    ((p as u64 * tiles as u64) / size as u64) as u32
}

/// The clusters of one view (`View`: a camera and image size), and what assigning lights to
/// them needs of it.
#[derive(Clone, Debug)]
pub struct ClusterGrid {
    pub dims: ClusterDims,
    pub width: u32,
    pub height: u32,
    pub near: f32,
    pub far: f32,
    /// Slice = ⌊ln(depth)·log_scale + log_bias⌋.
    pub log_scale: f32,
    pub log_bias: f32,
    /// The view's matrices, as the grid was cut (`View`; lights are assigned in view space).
    pub view: Mat4,
    pub projection: Mat4,
    /// Clip w at view depth d = a·d + b: (1, 0) perspective, (0, 1) orthographic.
    pub w_of_depth: (f32, f32),
    /// View-space bounds of every cluster, index = (z·Y + y)·X + x.
    pub bounds: Vec<Aabb>,
    /// The same boxes by axis: a cluster's x extent depends only on its tile column and
    /// slice, y only on row and slice, z only on slice (corners are tile rays × slice depths).
    /// Index z·X + x, z·Y + y and z.
    pub x_extents: Vec<(f32, f32)>,
    pub y_extents: Vec<(f32, f32)>,
    pub z_extents: Vec<(f32, f32)>,
    /// Depth where each slice starts, with slack (Z + 1 entries; the last is far).
    slice_starts: Vec<f32>,
    /// Tile of every pixel column and row (the assignment looks tiles up per light and slice;
    /// a table is much cheaper than the division).
    tile_of_column: Vec<u32>,
    tile_of_row: Vec<u32>,
}

/// Relative slack added to every cluster's box so that a fragment whose slice or tile was
/// rounded into a neighbour (f32 `log`, interpolation) is still covered. It only ever adds
/// lights whose contribution at the fragment is below (slack)²·(radius terms), i.e. nothing.
const SLACK: f32 = 1e-4;

impl ClusterGrid {
    /// The grid of `dims` clusters cut along `v`'s frustum.
    pub fn new(dims: ClusterDims, v: &View) -> ClusterGrid {
        let (width, height, camera) = (v.width, v.height, &v.camera);
        let (near, far) = (camera.near, camera.far);
        let ln_ratio = (far / near).ln();
        let log_scale = dims.z as f32 / ln_ratio;
        let log_bias = -(dims.z as f32) * near.ln() / ln_ratio;
        let mut grid = ClusterGrid {
            dims,
            width,
            height,
            near,
            far,
            log_scale,
            log_bias,
            view: v.view,
            projection: v.projection,
            w_of_depth: camera.w_of_depth(),
            bounds: Vec::with_capacity(dims.count()),
            slice_starts: Vec::new(),
            tile_of_column: Vec::new(),
            tile_of_row: Vec::new(),
            x_extents: Vec::new(),
            y_extents: Vec::new(),
            z_extents: Vec::new(),
        };
        // The tile spans below project with x_clip = p00·x, y_clip = p11·y, w = a·depth + b: a
        // symmetric perspective or orthographic projection, which is what `Camera::projection`
        // makes.
        let p = grid.projection;
        debug_assert!(p.z_axis.x == 0.0 && p.z_axis.y == 0.0 && p.w_axis.x == 0.0 && p.w_axis.y == 0.0);
        debug_assert!((-p.z_axis.w, p.w_axis.w) == grid.w_of_depth);
        grid.slice_starts = (0..=dims.z).map(|k| grid.slice_start(k)).collect();
        grid.tile_of_column = (0..width).map(|px| tile_of(px, dims.x, width)).collect();
        grid.tile_of_row = (0..height).map(|py| tile_of(py, dims.y, height)).collect();
        grid.bounds = grid.compute_bounds();
        let (x_extents, y_extents, z_extents) = grid.axis_extents();
        (grid.x_extents, grid.y_extents, grid.z_extents) = (x_extents, y_extents, z_extents);
        grid
    }

    /// Slice of a view depth (distance in front of the eye). Keep in sync with cluster.glsl.
    pub fn slice(&self, depth: f32) -> u32 {
        let s = (depth.ln() * self.log_scale + self.log_bias).floor();
        (s.max(0.0) as u32).min(self.dims.z - 1)
    }

    /// Depth where slice `k` starts (k = Z gives far).
    pub fn slice_start(&self, k: u32) -> f32 {
        self.near * (self.far / self.near).powf(k as f32 / self.dims.z as f32)
    }

    /// Whether a view-space sphere lies wholly outside one of the four side planes of the view
    /// frustum (so no pixel can see any of it).
    pub fn outside_side_planes(&self, centre: Vec3, radius: f32) -> bool {
        let (a, b) = self.w_of_depth;
        let w = a * -centre.z + b;
        let (p00, p11) = (self.projection.x_axis.x, self.projection.y_axis.y.abs());
        // Signed distance to the plane p·v = a·depth + b (outward positive) is
        // (p·v − a·depth − b)/√(p² + a²).
        let outside = |p: f32, v: f32| (p * v.abs() - w) > radius * (p * p + a * a).sqrt();
        outside(p00, centre.x) || outside(p11, centre.y)
    }

    /// 1 / clip w at view depth `depth` (> 0), what tile spans take.
    #[inline]
    pub fn inv_w(&self, depth: f32) -> f32 {
        1.0 / (self.w_of_depth.0 * depth + self.w_of_depth.1)
    }

    /// Depth range of slice `k`, widened by the slack the cluster boxes carry.
    pub fn slice_depths(&self, k: u32) -> (f32, f32) {
        (self.slice_starts[k as usize] * (1.0 - SLACK), self.slice_starts[k as usize + 1] * (1.0 + SLACK))
    }

    /// Tiles in x under the view-space box x ∈ [xa, xb], depth ∈ [d0, d1] (0 < d0 ≤ d1),
    /// given as `inv_depths` = (inv_w(d0), inv_w(d1)); None when the box is off screen. A shaded point
    /// projects to its pixel's centre, so a pixel of margin absorbs rounding.
    #[inline]
    pub fn tile_span_x(&self, xa: f32, xb: f32, inv_depths: (f32, f32)) -> Option<(u32, u32)> {
        let (lo, hi) = projected_span(self.projection.x_axis.x, xa, xb, inv_depths);
        pixel_span(lo, hi, self.width).map(|(a, b)| (self.tile_x(a), self.tile_x(b)))
    }

    /// As `tile_span_x` for rows (Vulkan: row 0 at the top, the projection flips y).
    #[inline]
    pub fn tile_span_y(&self, ya: f32, yb: f32, inv_depths: (f32, f32)) -> Option<(u32, u32)> {
        let (lo, hi) = projected_span(self.projection.y_axis.y, ya, yb, inv_depths);
        pixel_span(lo, hi, self.height).map(|(a, b)| (self.tile_y(a), self.tile_y(b)))
    }

    /// Tile of pixel column/row (integer arithmetic, as in the shader).
    pub fn tile_x(&self, px: u32) -> u32 {
        self.tile_of_column[px as usize]
    }

    pub fn tile_y(&self, py: u32) -> u32 {
        self.tile_of_row[py as usize]
    }

    pub fn index(&self, x: u32, y: u32, z: u32) -> u32 {
        (z * self.dims.y + y) * self.dims.x + x
    }

    /// The cluster of a fragment at pixel (px, py) with the given view depth.
    pub fn cluster_of(&self, px: u32, py: u32, depth: f32) -> u32 {
        self.index(self.tile_x(px), self.tile_y(py), self.slice(depth))
    }

    /// Pixel-centre span [first, last] + 0.5 that tile `t` of `tiles` covers in an axis of
    /// `size` pixels: pixels p with ⌊p·tiles/size⌋ = t.
    fn tile_centres(t: u32, tiles: u32, size: u32) -> (f32, f32) {
        let first = (t as u64 * size as u64).div_ceil(tiles as u64);
        let last = ((t as u64 + 1) * size as u64).div_ceil(tiles as u64) - 1;
        (first as f32 + 0.5, last as f32 + 0.5)
    }

    /// The boxes' extents per axis (see `x_extents`), read off the boxes.
    #[allow(clippy::type_complexity)]
    fn axis_extents(&self) -> (Vec<(f32, f32)>, Vec<(f32, f32)>, Vec<(f32, f32)>) {
        let d = self.dims;
        let b = |x: u32, y: u32, z: u32| self.bounds[self.index(x, y, z) as usize];
        let xs = (0..d.z).flat_map(|z| (0..d.x).map(move |x| (x, z))).map(|(x, z)| (b(x, 0, z).min.x, b(x, 0, z).max.x)).collect();
        let ys = (0..d.z).flat_map(|z| (0..d.y).map(move |y| (y, z))).map(|(y, z)| (b(0, y, z).min.y, b(0, y, z).max.y)).collect();
        let zs = (0..d.z).map(|z| (b(0, 0, z).min.z, b(0, 0, z).max.z)).collect();
        (xs, ys, zs)
    }

    fn compute_bounds(&self) -> Vec<Aabb> {
        // The view-space point of a pixel position at a depth: ndc = p·v / w, w = a·depth + b.
        let (p00, p11) = (self.projection.x_axis.x, self.projection.y_axis.y);
        let (a, b) = self.w_of_depth;
        let point = |px: f32, py: f32, depth: f32| {
            let ndc = (px / self.width as f32 * 2.0 - 1.0, py / self.height as f32 * 2.0 - 1.0);
            let w = a * depth + b;
            Vec3::new(ndc.0 / p00 * w, ndc.1 / p11 * w, -depth)
        };
        let d = self.dims;
        let mut bounds = Vec::with_capacity(d.count());
        for z in 0..d.z {
            let z0 = self.slice_start(z) * (1.0 - SLACK);
            let z1 = self.slice_start(z + 1) * (1.0 + SLACK);
            for y in 0..d.y {
                let (y0, y1) = Self::tile_centres(y, d.y, self.height);
                for x in 0..d.x {
                    let (x0, x1) = Self::tile_centres(x, d.x, self.width);
                    let (mut b_min, mut b_max) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
                    for (px, py) in [(x0, y0), (x1, y0), (x0, y1), (x1, y1)] {
                        for depth in [z0, z1] {
                            let p = point(px, py, depth);
                            b_min = b_min.min(p);
                            b_max = b_max.max(p);
                        }
                    }
                    let pad = (b_max - b_min).max(Vec3::splat(z1 - z0)) * SLACK;
                    bounds.push(Aabb { min: (b_min - pad).into(), max: (b_max + pad).into() });
                }
            }
        }
        bounds
    }
}
