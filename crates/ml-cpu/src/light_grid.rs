//! The world-space light grid (docs/DESIGN.md#the-light-grid): the GPU techniques' light
//! assignment. Cells of about the lights' radius over the box of the lights' centres; each
//! light is listed in the one cell that holds its centre (lights outside the box in the
//! nearest border cell), except the few widest, which every point tests ("wide" lights). A
//! point then tests the lights of the cells within `reach` of it — a handful of rows of
//! cells, each a contiguous run of the list — so what a pixel tests follows the lights near
//! it, not the total.
//!
//! This is the CPU model of what the GPU builds (light_grid_build.comp) and walks
//! (light_grid.glsl): the same f32 arithmetic, used to fit the grid and by the tests. The GPU
//! lists only the cells some point of the frame walks (its marks); the cells a point walks
//! hold the same lights as here, so what a point tests is the same.

use crate::gpu_types::PointLight;
use glam::{UVec3, Vec3};

/// The widest lights (at most this many, and at most one light in WIDE_SHARE) are tested by
/// every point instead of sizing the cells: one huge light among small ones would otherwise
/// make every cell huge.
pub const MAX_WIDE: usize = 256;
/// See MAX_WIDE.
pub const WIDE_SHARE: usize = 64;

/// Relative margin on `reach` when a point picks its cells (light_grid.glsl GRID_MARGIN): the
/// walk rounds differently than exact arithmetic; a light at the edge of its sphere gives
/// nothing, so a wider walk only tests a few more lights.
pub const GRID_MARGIN: f32 = 1e-4;

/// The most lists (cells and the wide lights') a grid has: 2^27 lists' ends of 4 B, within
/// what a device binds as one storage buffer.
pub const MAX_LISTS: u64 = 1 << 27;

/// Bytes per cell of the largest per-cell buffer the GPU binds (a list per cell: its count,
/// start, then end).
pub const LIST_BYTES: u64 = 4;

/// The cells a device binds as one storage buffer of lists, for its `maxStorageBufferRange`.
pub fn bindable_cells(max_storage_buffer_range: u32) -> u64 {
    u64::from(max_storage_buffer_range) / LIST_BYTES
}

/// The most cells a grid of `lights` lights gets where the device binds `bindable_lists`
/// cells (`bindable_cells`) as one storage buffer: cells about the lights' radius in a box
/// of uniform lights come to about one per light, so two per light keeps the scans and their
/// memory in proportion to the lights.
pub fn cell_budget(lights: usize, bindable_lists: u64) -> u64 {
    (2 * lights as u64 + 64).min(bindable_lists.saturating_sub(1)).clamp(1, MAX_LISTS - 1)
}

/// Where the grid lies and how it is cut (for lights at rest; a frame moves it with them).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightGridShape {
    /// The corner of cell (0, 0, 0), at rest.
    pub origin: Vec3,
    /// Edge of a cell.
    pub cell: f32,
    /// Cells per axis.
    pub dims: UVec3,
    /// The largest radius of a light in the cells: a point tests the cells within it.
    pub reach: f32,
    /// Lights wider than `reach`, which every point tests.
    pub wide: u32,
}

impl LightGridShape {
    /// The grid for `lights`: cells of edge `reach` (the widest light that is not wide), or
    /// larger where that would make more than `max_cells` cells.
    pub fn fit(lights: &[PointLight], max_cells: u64) -> LightGridShape {
        let reach = grid_reach(lights);
        let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
        for l in lights {
            let p = Vec3::from_slice(&l.position_radius[..3]);
            (lo, hi) = (lo.min(p), hi.max(p));
        }
        if lights.is_empty() {
            (lo, hi) = (Vec3::ZERO, Vec3::ZERO);
        }
        let extent = hi - lo;
        let max_cells = max_cells.max(1);
        // Never finer than a millionth of the extent per axis (dims stay far below u32).
        let mut cell = reach.max(extent.max_element() * 1e-6).max(f32::MIN_POSITIVE);
        loop {
            let dims = (extent / cell).floor().as_uvec3() + UVec3::ONE;
            if dims.as_u64vec3().element_product() <= max_cells {
                let wide = lights.iter().filter(|l| l.position_radius[3] > reach).count() as u32;
                return LightGridShape { origin: lo, cell, dims, reach, wide };
            }
            cell *= 1.26;
        }
    }

    /// Cells in all; the list's range `cells()` holds the wide lights.
    pub fn cells(&self) -> u32 {
        self.dims.element_product()
    }

    /// Corner of cell (0, 0, 0) when the lights moved by `offset`.
    pub fn origin_at(&self, offset: Vec3) -> Vec3 {
        self.origin + offset
    }

    /// The cell (x, y, z) holding `p` of a grid at `origin`, border cells holding all beyond.
    /// Keep in sync with light_grid.glsl grid_cell_coords.
    pub fn cell_coords(&self, origin: Vec3, p: Vec3) -> UVec3 {
        let g = (p - origin) * (1.0 / self.cell);
        g.floor().clamp(Vec3::ZERO, (self.dims - UVec3::ONE).as_vec3()).as_uvec3()
    }

    fn index(&self, c: UVec3) -> u32 {
        (c.z * self.dims.y + c.y) * self.dims.x + c.x
    }

    /// The list a light goes in when the grid is at `origin`: its cell, or `cells()` if wide.
    /// Keep in sync with light_grid_build.comp.
    pub fn list_of(&self, origin: Vec3, light: &PointLight) -> u32 {
        if light.position_radius[3] > self.reach {
            return self.cells();
        }
        self.index(self.cell_coords(origin, Vec3::from_slice(&light.position_radius[..3])))
    }

    /// The runs of cells (first, last: one row along x) a point `p` tests, in the order the
    /// shader walks them. Keep in sync with light_grid.glsl SUM_GRID_LIGHTS.
    pub fn rows_near(&self, origin: Vec3, p: Vec3) -> Vec<(u32, u32)> {
        let inv = 1.0 / self.cell;
        let g = (p - origin) * inv;
        let r = self.reach * inv * (1.0 + GRID_MARGIN);
        let top = (self.dims - UVec3::ONE).as_vec3();
        let lo = (g - r).floor().clamp(Vec3::ZERO, top).as_uvec3();
        let hi = (g + r).floor().clamp(Vec3::ZERO, top).as_uvec3();
        let mut rows = Vec::new();
        for z in lo.z..=hi.z {
            let dz = slab_distance(g.z, z, self.dims.z);
            for y in lo.y..=hi.y {
                let dy = slab_distance(g.y, y, self.dims.y);
                let h2 = r * r - dy * dy - dz * dz;
                if h2 < 0.0 {
                    continue;
                }
                let h = h2.sqrt();
                let x0 = (g.x - h).floor().clamp(0.0, top.x) as u32;
                let x1 = (g.x + h).floor().clamp(0.0, top.x) as u32;
                rows.push((self.index(UVec3::new(x0, y, z)), self.index(UVec3::new(x1, y, z))));
            }
        }
        rows
    }
}

/// Distance in cells from `g` to the slab of cell `c` along an axis of `n` cells, border
/// cells reaching to infinity (they hold the lights beyond the grid).
fn slab_distance(g: f32, c: u32, n: u32) -> f32 {
    let below = if c == 0 { 0.0 } else { c as f32 - g };
    let above = if c + 1 == n { 0.0 } else { g - (c + 1) as f32 };
    below.max(above).max(0.0)
}

/// The radius that sizes the cells: the largest once the wide lights (`MAX_WIDE`,
/// `WIDE_SHARE`) are left out — those strictly wider are wide.
pub fn grid_reach(lights: &[PointLight]) -> f32 {
    let wide = (lights.len() / WIDE_SHARE).min(MAX_WIDE);
    let mut radii: Vec<f32> = lights.iter().map(|l| l.position_radius[3]).collect();
    if radii.is_empty() {
        return 1.0;
    }
    // The (wide + 1)-th largest.
    let k = radii.len() - 1 - wide;
    *radii.select_nth_unstable_by(k, f32::total_cmp).1
}

/// The lights in the order of their lists at rest (cell after cell, the wide lights last;
/// within a list in the scene's order): the order the GPU keeps them in, so that the build's
/// neighbouring threads count into neighbouring cells and a cell's lights lie side by side.
/// Returns, per place, the light's index in `lights`.
pub fn grid_order(shape: &LightGridShape, lights: &[PointLight]) -> Vec<u32> {
    let lists: Vec<u32> = lights.iter().map(|l| shape.list_of(shape.origin, l)).collect();
    let mut start = vec![0u32; shape.cells() as usize + 2];
    for &l in &lists {
        start[l as usize + 1] += 1;
    }
    for i in 1..start.len() {
        start[i] += start[i - 1];
    }
    let mut order = vec![0u32; lights.len()];
    for (i, &l) in lists.iter().enumerate() {
        order[start[l as usize] as usize] = i as u32;
        start[l as usize] += 1;
    }
    order
}

/// A CPU build of the lists for lights moved by `offset`: per list (every cell, then the
/// wide lights) the indices of its lights in ascending order.
pub fn cpu_lists(shape: &LightGridShape, lights: &[PointLight], offset: Vec3) -> Vec<Vec<u32>> {
    let origin = shape.origin_at(offset);
    let mut lists = vec![Vec::new(); shape.cells() as usize + 1];
    for (i, l) in lights.iter().enumerate() {
        let mut moved = *l;
        for (c, d) in moved.position_radius.iter_mut().zip(offset.to_array()) {
            *c += d;
        }
        lists[shape.list_of(origin, &moved) as usize].push(i as u32);
    }
    lists
}

/// How many lights a point at `p` tests: the wide ones and those of its rows.
pub fn tested_at(shape: &LightGridShape, lists: &[Vec<u32>], offset: Vec3, p: Vec3) -> usize {
    let wide = lists[shape.cells() as usize].len();
    wide + shape
        .rows_near(shape.origin_at(offset), p)
        .iter()
        .map(|&(a, b)| (a..=b).map(|c| lists[c as usize].len()).sum::<usize>())
        .sum::<usize>()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(p: Vec3, r: f32) -> PointLight {
        PointLight { position_radius: [p.x, p.y, p.z, r], color: [1.0; 4] }
    }

    /// A small random generator (tests only).
    fn rng(seed: u64) -> impl FnMut() -> f32 {
        let mut s = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        move || {
            s = s.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (s >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn every_light_that_reaches_a_point_is_in_a_row_it_tests() {
        for seed in 0..20 {
            let mut next = rng(seed);
            let count = 50 + (next() * 3000.0) as usize;
            let lights: Vec<PointLight> = (0..count)
                .map(|i| {
                    let p = Vec3::new(next(), next(), next()) * 20.0 - 10.0;
                    // Mostly small, a few huge (wide), some tiny.
                    let r = if i % 97 == 0 {
                        5.0 + next() * 20.0
                    } else if i % 3 == 0 {
                        1e-3
                    } else {
                        0.1 + next() * 1.5
                    };
                    light(p, r)
                })
                .collect();
            let max_cells = if seed % 4 == 0 { 64 } else { 2 * count as u64 };
            let shape = LightGridShape::fit(&lights, max_cells);
            assert!(u64::from(shape.cells()) <= max_cells.max(1));
            // Moved, so that some lights leave the grid's box and points lie far outside it.
            let offset = Vec3::new(next() - 0.5, 0.0, next() - 0.5) * 6.0;
            let lists = cpu_lists(&shape, &lights, offset);
            assert_eq!(lists.iter().map(Vec::len).sum::<usize>(), count, "each light listed once");
            let origin = shape.origin_at(offset);
            for _ in 0..300 {
                let p = Vec3::new(next(), next(), next()) * 36.0 - 18.0;
                let mut seen: Vec<u32> = lists[shape.cells() as usize].clone();
                for (a, b) in shape.rows_near(origin, p) {
                    assert!(a <= b && b - a < shape.dims.x, "a row is one run along x");
                    seen.extend((a..=b).flat_map(|c| lists[c as usize].iter().copied()));
                }
                for (i, l) in lights.iter().enumerate() {
                    let q = Vec3::from_slice(&l.position_radius[..3]) + offset;
                    if q.distance(p) < l.position_radius[3] {
                        assert!(seen.contains(&(i as u32)), "seed {seed}: light {i} reaches {p} but is not tested");
                    }
                }
            }
        }
    }

    #[test]
    fn uniform_lights_test_a_few_times_those_reaching() {
        // Lights uniform in a box with the bench scene's density (about 4 reach a point).
        let mut next = rng(9);
        let count = 20_000;
        let side = 40.0f32;
        let r = (4.0 * side.powi(3) / (count as f32 * 4.0 / 3.0 * std::f32::consts::PI)).cbrt();
        let lights: Vec<PointLight> = (0..count).map(|_| light(Vec3::new(next(), next(), next()) * side, r)).collect();
        let shape = LightGridShape::fit(&lights, 2 * count as u64);
        assert_eq!(shape.reach, r);
        let lists = cpu_lists(&shape, &lights, Vec3::ZERO);
        let (mut tested, mut reached) = (0, 0);
        for _ in 0..2000 {
            let p = Vec3::new(next(), next(), next()) * (side - 2.0 * r) + r;
            tested += tested_at(&shape, &lists, Vec3::ZERO, p);
            reached += lights.iter().filter(|l| Vec3::from_slice(&l.position_radius[..3]).distance(p) < r).count();
        }
        let ratio = tested as f64 / reached as f64;
        assert!(ratio < 6.0, "{tested} tested for {reached} reaching: {ratio:.2}");
    }

    #[test]
    fn the_grid_order_lists_cell_after_cell() {
        let mut next = rng(3);
        let lights: Vec<PointLight> =
            (0..2000).map(|i| light(Vec3::new(next(), next(), next()) * 10.0, if i == 5 { 50.0 } else { 0.4 })).collect();
        let shape = LightGridShape::fit(&lights, 4000);
        let order = grid_order(&shape, &lights);
        let mut sorted = order.clone();
        sorted.sort_unstable();
        assert_eq!(sorted, (0..2000).collect::<Vec<u32>>(), "a permutation");
        let lists: Vec<u32> = order.iter().map(|&i| shape.list_of(shape.origin, &lights[i as usize])).collect();
        assert!(lists.windows(2).all(|w| w[0] <= w[1]), "in list order");
        assert_eq!(*lists.last().unwrap(), shape.cells(), "the wide light last");
        assert_eq!(lists.iter().filter(|&&l| l == shape.cells()).count(), shape.wide as usize, "the build counts the last `wide` as wide");
    }

    #[test]
    fn the_widest_lights_do_not_size_the_cells() {
        let mut lights: Vec<PointLight> = (0..640).map(|i| light(Vec3::splat(i as f32), 0.5)).collect();
        lights[7].position_radius[3] = 1000.0;
        let shape = LightGridShape::fit(&lights, 10_000);
        assert_eq!(shape.reach, 0.5);
        assert_eq!(shape.list_of(shape.origin, &lights[7]), shape.cells());
        // Fewer than WIDE_SHARE lights: none is wide.
        assert_eq!(grid_reach(&lights[..40]), 1000.0);
    }
}
