use super::*;
use crate::camera::{Camera, View};
use crate::gpu_types::PointLight;
use crate::lights::LightParams;
use crate::random_scene::{hostile_lights, random_camera};
use glam::{Vec3, Vec4, Vec4Swizzles};
use rand::{Rng, SeedableRng};

const W: u32 = 320;
const H: u32 = 180;

fn light(p: Vec3, r: f32) -> PointLight {
    PointLight { position_radius: [p.x, p.y, p.z, r], color: [1.0; 4] }
}

fn assign(grid: &ClusterGrid, lights: &[PointLight]) -> ClusterLists {
    let mut out = ClusterLists::default();
    ClusterAssigner::new().assign(grid, lights, &mut out, usize::MAX).expect("no limit");
    out
}

/// World position of the point seen through the centre of pixel (px, py) at view depth z.
/// (Perspective or orthographic: unprojected at the NDC depth that view depth has.)
fn world_point(grid: &ClusterGrid, px: u32, py: u32, depth: f32) -> Vec3 {
    let clip_z = grid.projection * Vec4::new(0.0, 0.0, -depth, 1.0);
    let ndc = Vec4::new(
        (px as f32 + 0.5) / grid.width as f32 * 2.0 - 1.0,
        (py as f32 + 0.5) / grid.height as f32 * 2.0 - 1.0,
        clip_z.z / clip_z.w,
        1.0,
    );
    let v = grid.projection.inverse() * ndc;
    let view_point = v.xyz() / v.w;
    (grid.view.inverse() * view_point.extend(1.0)).xyz()
}

fn seed_camera_grid(dims: ClusterDims) -> ClusterGrid {
    ClusterGrid::new(dims, &View::new(Camera::seed(), W, H))
}

#[test]
fn slice_formula_follows_its_definition_and_its_boundaries() {
    let grid = seed_camera_grid(ClusterDims::DEFAULT);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let z = grid.dims.z as f64;
    let (mut off_boundary, mut mismatched) = (0, 0);
    for _ in 0..100_000 {
        let depth: f32 = rng.random_range(grid.near..grid.far);
        let exact = (depth as f64 / grid.near as f64).ln() / (grid.far as f64 / grid.near as f64).ln() * z;
        let expected = (exact.floor() as u32).min(grid.dims.z - 1);
        if (exact - exact.round()).abs() > 1e-4 {
            off_boundary += 1;
            if grid.slice(depth) != expected {
                mismatched += 1;
            }
        }
    }
    assert!(off_boundary > 99_000);
    assert_eq!(mismatched, 0);
    for k in 0..grid.dims.z {
        let mid = (grid.slice_start(k) * grid.slice_start(k + 1)).sqrt();
        assert_eq!(grid.slice(mid), k);
    }
    assert_eq!(grid.slice(grid.near * 0.5), 0);
    assert_eq!(grid.slice(grid.far * 2.0), grid.dims.z - 1);
}

#[test]
fn cluster_dims_parse() {
    assert_eq!(ClusterDims::parse("16x9x24"), Ok(ClusterDims::DEFAULT));
    assert_eq!(ClusterDims::parse("4x4x2"), Ok(ClusterDims { x: 4, y: 4, z: 2 }));
    for bad in ["", "16x9", "0x9x24", "16x9x24x2", "axbxc", "2000x2000x2000"] {
        assert!(ClusterDims::parse(bad).is_err(), "{bad}");
    }
}

/// Every (light, point) pair with distance < radius is in that point's cluster list, for
/// points on the pixel-centre rays of random pixels at random depths. Reports the waste:
/// listed lights per light that really reaches the point.
#[test]
fn no_light_that_reaches_a_point_is_missing_from_its_cluster() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let (mut listed, mut reaching) = (0u64, 0u64);
    for scene in 0..24 {
        let camera = random_camera(&mut rng);
        let dims = if scene % 3 == 0 { ClusterDims { x: 4, y: 4, z: 2 } } else { ClusterDims::DEFAULT };
        let grid = ClusterGrid::new(dims, &View::new(camera, W, H));
        let count = rng.random_range(1..3000);
        let lights = hostile_lights(&mut rng, &camera, count);
        let lists = assign(&grid, &lights);
        let view_proj = grid.projection * grid.view;
        let mut samples = Vec::new();
        for _ in 0..2000 {
            // Anywhere: random pixels at depths spread like the slices (uniform in log depth).
            let depth = grid.near * (grid.far / grid.near).powf(rng.random_range(0.0..1.0));
            samples.push((rng.random_range(0..W), rng.random_range(0..H), depth));
            // Near the rim of a light's sphere, where a too-tight tile or slice range shows.
            let l = &lights[rng.random_range(0..lights.len())];
            let dir =
                Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)).normalize_or(Vec3::X);
            let q = Vec3::from_slice(&l.position_radius[..3]) + dir * l.position_radius[3] * rng.random_range(0.9..1.0);
            let clip = view_proj * q.extend(1.0);
            let (depth, ndc) = (-(grid.view * q.extend(1.0)).z, clip.xyz() / clip.w);
            if depth > grid.near && depth < grid.far && ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0 {
                let px = (((ndc.x + 1.0) * 0.5 * W as f32) as u32).min(W - 1);
                let py = (((ndc.y + 1.0) * 0.5 * H as f32) as u32).min(H - 1);
                samples.push((px, py, depth));
            }
        }
        for (px, py, depth) in samples {
            let p = world_point(&grid, px, py, depth);
            let cluster = lists.lights_of(grid.cluster_of(px, py, depth));
            listed += cluster.len() as u64;
            for (i, l) in lights.iter().enumerate() {
                let centre = Vec3::from_slice(&l.position_radius[..3]);
                if centre.distance(p) < l.position_radius[3] {
                    reaching += 1;
                    assert!(
                        cluster.binary_search(&(i as u32)).is_ok(),
                        "scene {scene}: light {i} reaches pixel ({px},{py}) at depth {depth} but is not in its cluster"
                    );
                }
            }
        }
    }
    println!("conservative waste: {:.2} listed lights per light that reaches the point", listed as f64 / reaching as f64);
    assert!(reaching > 10_000, "the scenes should light many points, got {reaching}");
}

#[test]
fn lists_are_sorted_and_match_the_per_light_test() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let camera = random_camera(&mut rng);
    let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(camera, W, H));
    let lights = hostile_lights(&mut rng, &camera, 5000);
    let lists = assign(&grid, &lights);
    let mut expected = vec![Vec::new(); grid.dims.count()];
    for (i, l) in lights.iter().enumerate() {
        super::assign::light_clusters(&grid, l, |c| expected[c as usize].push(i as u32));
    }
    for (c, want) in expected.iter().enumerate() {
        assert_eq!(lists.lights_of(c as u32), &want[..], "cluster {c}");
    }
    let stats = lists.stats();
    assert_eq!(stats.index_len, lists.indices.len());
    assert!(stats.max_lights > 0);
}

// ---- The five clustering mistakes of the demo the seed scene comes from
// (docs/DESIGN.md#mistakes-we-avoid), each with a case the demo's code gets wrong. ----

/// The demo's tile range: screen extent radius/w in NDC, clamped to 0.5.
fn seed_tile_range(grid: &ClusterGrid, l: &PointLight) -> Option<(u32, u32, u32, u32)> {
    let clip = grid.projection * grid.view * Vec4::new(l.position_radius[0], l.position_radius[1], l.position_radius[2], 1.0);
    if clip.w <= 0.0 {
        return None; // mistake 3: centre behind the camera → skipped
    }
    let ndc = clip.xyz() / clip.w;
    let r = (l.position_radius[3] / clip.w).min(0.5);
    let tile = |v: f32, n: u32| ((((v.clamp(-1.0, 1.0) + 1.0) * 0.5) * n as f32) as u32).min(n - 1);
    Some((tile(ndc.x - r, grid.dims.x), tile(ndc.x + r, grid.dims.x), tile(ndc.y - r, grid.dims.y), tile(ndc.y + r, grid.dims.y)))
}

#[test]
fn mistake_1_ndc_radius_approximation_misses_tiles_that_a_near_light_lights() {
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 60.0, 0.1, 256.0);
    let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(camera, W, H));
    // A light 3 in front of the eye with radius 6 lights the whole screen at depth 3.
    let l = light(Vec3::new(0.0, 0.0, 2.0), 6.0);
    let p = world_point(&grid, 0, 0, 3.0); // top-left corner pixel
    assert!(p.distance(Vec3::new(0.0, 0.0, 2.0)) < 6.0);
    let (x0, _, y0, _) = seed_tile_range(&grid, &l).unwrap();
    assert!(x0 > 0 && y0 > 0, "the seed's range should miss tile (0,0): it starts at ({x0},{y0})");
    let lists = assign(&grid, &[l]);
    assert_eq!(lists.lights_of(grid.cluster_of(0, 0, 3.0)), &[0]);
}

#[test]
fn mistake_2_ndc_depth_is_not_linear_depth() {
    let grid = seed_camera_grid(ClusterDims::DEFAULT);
    // The seed's slice: NDC z (0..1) times Z, as if linear.
    let seed_slice = |depth: f32| {
        let clip = grid.projection * Vec4::new(0.0, 0.0, -depth, 1.0);
        ((clip.z / clip.w * grid.dims.z as f32) as u32).min(grid.dims.z - 1)
    };
    // From 1 m to the far plane the seed uses only the last few slices ...
    let seed_used: std::collections::BTreeSet<u32> = (10..2560).map(|d| seed_slice(d as f32 * 0.1)).collect();
    assert!(seed_used.len() <= 3, "seed slices for 1..256 m: {seed_used:?}");
    // ... where the exponential slicing spreads them over most of the grid.
    let ours: std::collections::BTreeSet<u32> = (10..2560).map(|d| grid.slice(d as f32 * 0.1)).collect();
    assert!(ours.len() >= 16, "{ours:?}");
}

#[test]
fn mistake_3_lights_behind_the_camera_still_light_what_is_in_front() {
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 60.0, 0.1, 256.0);
    let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(camera, W, H));
    let l = light(Vec3::new(0.0, 0.0, 6.0), 3.0); // 1 behind the eye, reaches 2 in front
    assert!(seed_tile_range(&grid, &l).is_none(), "the seed skips it");
    let p = world_point(&grid, W / 2, H / 2, 1.5);
    assert!(p.distance(Vec3::new(0.0, 0.0, 6.0)) < 3.0);
    let lists = assign(&grid, &[l]);
    assert_eq!(lists.lights_of(grid.cluster_of(W / 2, H / 2, 1.5)), &[0]);
}

#[test]
fn mistake_4_no_fixed_capacity_drops_lights() {
    // The seed's per-cluster arrays stopped adding at a fixed size; 10,000 overlapping
    // lights must all be listed.
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 60.0, 0.1, 256.0);
    let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(camera, W, H));
    let lights: Vec<PointLight> = (0..10_000).map(|i| light(Vec3::new(0.0, (i as f32) * 1e-5, 0.0), 2.0)).collect();
    let lists = assign(&grid, &lights);
    let centre = lists.lights_of(grid.cluster_of(W / 2, H / 2, 5.0));
    assert_eq!(centre.len(), 10_000);
    assert!(centre.windows(2).all(|w| w[0] < w[1]));
}

#[test]
fn mistake_5_gpu_structs_have_no_std140_padding() {
    // The seed padded every uint of its index list to 16 bytes (a std140 array) and kept
    // lights in a 64 KiB uniform buffer. Ours: std430 storage buffers, 8-byte ranges and a
    // 4-byte index stride (the shader side is checked by the SPIR-V reflection test
    // `gpu_layout`, which also checks the index array's stride).
    assert_eq!(std::mem::size_of::<crate::gpu_types::ClusterRange>(), 8);
    let lists = assign(&seed_camera_grid(ClusterDims::DEFAULT), &LightParams::seed_default().build().unwrap());
    assert_eq!(std::mem::size_of_val(&lists.indices[..]), lists.indices.len() * 4);
}

#[test]
fn assignment_stops_at_its_limit_instead_of_exhausting_memory() {
    let grid = seed_camera_grid(ClusterDims::DEFAULT);
    let lights: Vec<PointLight> = (0..2000).map(|i| light(Vec3::new(0.0, i as f32 * 1e-3, 0.0), 40.0)).collect();
    let mut out = ClusterLists::default();
    let err = ClusterAssigner::new().assign(&grid, &lights, &mut out, 10_000).unwrap_err();
    assert!(err.at_least > 10_000);
    // Within the limit it succeeds.
    ClusterAssigner::new().assign(&grid, &lights[..2], &mut out, 10_000).unwrap();
}

/// The up-front count is what the assignment lists with no motion, never more than any moved
/// frame's lists, and stops early past its limit.
#[test]
fn counted_entries_bound_every_frames_lists() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    for seed in 0..6u64 {
        let camera = random_camera(&mut rng);
        let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(camera, W, H));
        let lights = hostile_lights(&mut rng, &camera, 400);
        let exact = assign(&grid, &lights).indices.len();
        let still = count_entries(&grid, &lights, 0.0, usize::MAX);
        assert!(still <= exact && still as f64 >= exact as f64 * 0.999, "seed {seed}: without motion {still} of {exact}");
        let motion = 0.3;
        let bound = count_entries(&grid, &lights, motion, usize::MAX);
        assert!(bound <= exact, "seed {seed}");
        for t in [0.0f32, 0.125, 0.4, 0.77] {
            let moved: Vec<PointLight> = lights
                .iter()
                .map(|l| {
                    let d = crate::lights::motion_offset(t, motion);
                    let p = l.position_radius;
                    PointLight { position_radius: [p[0] + d.x, p[1] + d.y, p[2] + d.z, p[3]], color: l.color }
                })
                .collect();
            let listed = assign(&grid, &moved).indices.len();
            assert!(bound <= listed, "seed {seed}, t {t}: counted {bound}, listed {listed}");
        }
    }
    // Huge lights: the count stops soon after the limit.
    let grid = seed_camera_grid(ClusterDims::DEFAULT);
    let huge: Vec<PointLight> = (0..100_000).map(|i| light(Vec3::new(0.0, i as f32 * 1e-5, 0.0), 400.0)).collect();
    let counted = count_entries(&grid, &huge, 0.0, 1_000_000);
    assert!(counted > 1_000_000 && counted < 1_000_000 + 64 * 1024 * ClusterDims::DEFAULT.count(), "{counted}");
}

#[test]
fn cluster_boxes_are_separable_by_axis() {
    // The assignment tests x, y and z extents separately; that is the box test only if every
    // box is the product of its column's, row's and slice's extents.
    for dims in [ClusterDims::DEFAULT, ClusterDims { x: 4, y: 4, z: 2 }, ClusterDims { x: 7, y: 5, z: 3 }] {
        let grid = seed_camera_grid(dims);
        for z in 0..dims.z {
            for y in 0..dims.y {
                for x in 0..dims.x {
                    let b = grid.bounds[grid.index(x, y, z) as usize];
                    assert_eq!((b.min.x, b.max.x), grid.x_extents[(z * dims.x + x) as usize]);
                    assert_eq!((b.min.y, b.max.y), grid.y_extents[(z * dims.y + y) as usize]);
                    assert_eq!((b.min.z, b.max.z), grid.z_extents[z as usize]);
                }
            }
        }
    }
}

#[test]
fn auto_grids_grow_with_the_cube_root_of_the_light_count() {
    let auto = |n, w, h| {
        let d = ClusterDims::for_lights(n, w, h);
        (d.x, d.y, d.z)
    };
    // The default up to ~11.6k lights (s = 1 while ∛(N/4096) < √2).
    for n in [0, 1, 64, 1000, 4096, 11_000] {
        assert_eq!(auto(n, 1920, 1080), (16, 9, 24), "{n}");
    }
    assert_eq!(auto(16_000, 1920, 1080), (32, 18, 48));
    for n in [256_000, 1_000_000, 50_000_000] {
        assert_eq!(auto(n, 1920, 1080), (64, 36, 96), "{n}");
    }
    // Tiles stay at least 16 px when scaling up, and never fall below the default grid.
    assert_eq!(auto(1_000_000, 640, 360), (40, 22, 96));
    assert_eq!(auto(1_000_000, 64, 64), (16, 9, 96));
    assert!(ClusterDims::for_lights(usize::MAX, u32::MAX, u32::MAX).count() as u64 <= crate::limits::MAX_CLUSTERS);
}
