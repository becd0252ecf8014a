use super::*;
use rand::{Rng, SeedableRng};

const MIB: u64 = 1 << 20;

fn light(x: f32, y: f32, z: f32, radius: f32) -> PlannedLight {
    PlannedLight { position: Vec3::new(x, y, z), radius }
}

fn camera() -> Camera {
    Camera::looking_at(Vec3::new(0.0, 2.0, 10.0), Vec3::new(0.0, 2.0, 0.0), 60.0, 0.1, 100.0)
}

/// A fresh atlas's plan for `lights` (keys: their indices) at 1920×1080.
fn plan(lights: &[PlannedLight], c: &Camera, budget: u64) -> Result<AtlasPlan, AtlasError> {
    let keyed: Vec<(u32, PlannedLight)> = lights.iter().enumerate().map(|(i, l)| (i as u32, *l)).collect();
    ShadowAtlas::new(budget)?.plan(&keyed, c, (1920, 1080), None, true)
}

#[test]
fn a_face_has_about_as_many_texels_as_its_light_covers_pixels() {
    let c = camera();
    // Far and small: the smallest; the eye inside: the largest.
    assert_eq!(face_size(&light(0.0, 2.0, -80.0, 0.1), &c, 1080), MIN_FACE);
    assert_eq!(face_size(&light(0.0, 2.0, 9.0, 3.0), &c, 1080), MAX_FACE);
    // A sphere of radius 1 at distance 10 spans 2·tan(asin(0.1)) / (2·tan 30°) of the height:
    // 0.174 · 1080 = 188 pixels → 256.
    assert_eq!(face_size(&light(0.0, 2.0, 0.0, 1.0), &c, 1080), 256);
    // Nearer is never smaller.
    let sizes: Vec<u32> = (1..40).map(|i| face_size(&light(0.0, 2.0, 10.0 - i as f32 * 2.0, 1.0), &c, 1080)).collect();
    assert!(sizes.windows(2).all(|w| w[0] >= w[1]), "{sizes:?}");
    assert!(sizes.iter().all(|s| s.is_power_of_two()));
}

#[test]
fn faces_outside_the_view_are_dropped_and_seen_ones_kept() {
    let c = camera();
    let planes = frustum_planes(c.projection(16.0 / 9.0) * c.view());
    // Behind the camera, out of reach of the frustum: nothing.
    assert_eq!(visible_faces(&light(0.0, 2.0, 20.0, 1.0), &planes), 0);
    // In front and wholly in view: the camera sees around it on every side.
    assert_eq!(visible_faces(&light(0.0, 2.0, 0.0, 1.0), &planes), 0b11_1111);
    // Far to the right, reaching into the view only on its −X side: +X is dropped.
    let right = visible_faces(&light(16.0, 2.0, 0.0, 7.0), &planes);
    assert_ne!(right & (1 << 1), 0, "−X reaches into the view");
    assert_eq!(right & 1, 0, "+X points away from the view");
    // Behind the camera but reaching past the near plane: the faces towards the view kept.
    let around_eye = visible_faces(&light(0.0, 2.0, 10.5, 2.0), &planes);
    assert_ne!(around_eye & (1 << 5), 0, "−Z looks where the camera looks");
}

/// The property the shading relies on: any point of the view that a light reaches lies in a
/// face the plan keeps — also on cube seams and near the frustum's edges, with the eye inside
/// light spheres.
#[test]
fn every_visible_point_a_light_reaches_is_in_a_kept_face() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let (width, height) = (160u32, 90u32);
    for trial in 0..200 {
        let eye = Vec3::new(rng.random_range(-5.0..5.0), rng.random_range(0.0..5.0), rng.random_range(-5.0..5.0));
        let target = eye + Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)).normalize();
        let c = Camera::looking_at(eye, target, rng.random_range(30.0..90.0), 0.1, rng.random_range(5.0..50.0));
        let view_proj = c.projection(width as f32 / height as f32) * c.view();
        let planes = frustum_planes(view_proj);
        let inverse = view_proj.inverse();
        // Lights around the eye (often containing it) and further out.
        let l = light(
            eye.x + rng.random_range(-6.0..6.0),
            eye.y + rng.random_range(-6.0..6.0),
            eye.z + rng.random_range(-6.0..6.0),
            rng.random_range(0.2..8.0),
        );
        let mask = visible_faces(&l, &planes);
        for _ in 0..400 {
            // A point seen by the camera: a random pixel at a random depth.
            let ndc = Vec4::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(0.0..1.0), 1.0);
            let p = inverse * ndc;
            let p = p.truncate() / p.w;
            let d = p - l.position;
            if d.length() > l.radius || d.length() < 1e-4 {
                continue;
            }
            // Every face whose pyramid holds the point (two or three on a seam).
            for face in 0..6 {
                let (forward, up) = face_axes(face);
                let side = forward.cross(up);
                let along = d.dot(forward);
                if along > 0.0 && d.dot(side).abs() <= along && d.dot(up).abs() <= along {
                    assert_ne!(mask & (1 << face), 0, "trial {trial}: face {face} of {l:?} holds {p}, seen by {c:?}, dropped");
                }
            }
        }
    }
}

#[test]
fn the_atlas_is_as_many_blocks_as_the_bytes_hold() {
    let blocks = |mib: u64| AtlasBlocks::for_bytes(mib * MIB).map(|b| (b.side, b.count, b.extent()));
    assert_eq!(blocks(256).unwrap(), (2048, 16, [8192, 8192]));
    assert_eq!(blocks(200).unwrap(), (2048, 12, [8192, 6144]));
    assert_eq!(blocks(16).unwrap(), (2048, 1, [2048, 2048]));
    assert_eq!(blocks(8).unwrap(), (1024, 2, [2048, 1024]));
    assert_eq!(blocks(48).unwrap(), (2048, 3, [4096, 4096]));
    assert_eq!(blocks(1).unwrap(), (512, 1, [512, 512]));
    assert!(matches!(AtlasBlocks::for_bytes(1000), Err(AtlasError::BudgetTooSmall { .. })));
    assert!(matches!(AtlasBlocks::for_bytes(0), Err(AtlasError::BudgetTooSmall { .. })));
}

/// Tiles lie inside the atlas and never overlap.
fn assert_packed(plan: &AtlasPlan) {
    let [w, h] = plan.blocks.extent();
    for t in &plan.tiles {
        assert!(t.origin[0] + t.size <= w && t.origin[1] + t.size <= h, "{t:?} outside {w}x{h}");
        assert!(t.origin[0] % t.size == 0 && t.origin[1] % t.size == 0, "{t:?} not aligned to its size");
        // Its run of Z-ordered texels is its square of the picture.
        let side = plan.blocks.side;
        let block = (t.origin[1] / side) * plan.blocks.columns + t.origin[0] / side;
        let corner = block as u64 * side as u64 * side as u64;
        assert_eq!(t.base, corner + morton_encode(t.origin[0] % side, t.origin[1] % side), "{t:?}");
    }
    let mut tiles = plan.tiles.clone();
    tiles.sort_by_key(|t| (t.origin[1], t.origin[0]));
    for (i, a) in tiles.iter().enumerate() {
        for b in &tiles[i + 1..] {
            let apart = a.origin[0] + a.size <= b.origin[0]
                || b.origin[0] + b.size <= a.origin[0]
                || a.origin[1] + a.size <= b.origin[1]
                || b.origin[1] + b.size <= a.origin[1];
            assert!(apart, "{a:?} overlaps {b:?}");
        }
    }
    assert!(plan.used_bytes() <= plan.atlas_bytes());
}

#[test]
fn tiles_lie_inside_the_atlas_and_never_overlap() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let c = camera();
    for budget in [16 * MIB, 100 * MIB, 256 * MIB] {
        let lights: Vec<PlannedLight> = (0..300)
            .map(|_| {
                light(rng.random_range(-20.0..20.0), rng.random_range(0.0..6.0), rng.random_range(-30.0..8.0), rng.random_range(0.5..6.0))
            })
            .collect();
        let plan = plan(&lights, &c, budget).unwrap();
        assert_packed(&plan);
        assert!(plan.atlas_bytes() <= budget);
        println!(
            "{} MiB: {} faces, divided by {}, {} of {} MiB used",
            budget >> 20,
            plan.tiles.len(),
            plan.divided_by,
            plan.used_bytes() >> 20,
            plan.atlas_bytes() >> 20
        );
    }
}

/// 4,096 shadowed lights, most of them near the camera and large on screen: the budget is
/// never exceeded, every visible face keeps a tile, every face is divided by the same factor.
#[test]
fn four_thousand_lights_fit_the_budget_by_one_factor() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(4);
    let c = camera();
    let lights: Vec<PlannedLight> = (0..4096)
        .map(|_| light(rng.random_range(-8.0..8.0), rng.random_range(0.0..4.0), rng.random_range(-10.0..9.0), rng.random_range(1.0..4.0)))
        .collect();
    let planes = frustum_planes(c.projection(16.0 / 9.0) * c.view());
    let visible: usize = lights.iter().map(|l| visible_faces(l, &planes).count_ones() as usize).sum();
    let planned = plan(&lights, &c, 256 * MIB).unwrap();
    assert_eq!(planned.tiles.len(), visible, "a visible face without a tile");
    assert!(planned.divided_by > 1, "these faces should not fit undivided");
    for t in &planned.tiles {
        let wanted = face_size(&lights[t.light as usize], &c, 1080);
        assert_eq!(t.size, (wanted / planned.divided_by).max(MIN_FACE), "{t:?}");
    }
    assert_packed(&planned);
    assert!(planned.atlas_bytes() <= 256 * MIB);
    println!(
        "{visible} faces divided by {}: {} MiB of {} MiB",
        planned.divided_by,
        planned.used_bytes() >> 20,
        planned.atlas_bytes() >> 20
    );
    // Too small for even the smallest faces: an error with the numbers, not a dropped shadow.
    let err = plan(&lights, &c, 4 * MIB).unwrap_err();
    assert!(matches!(err, AtlasError::TooManyFaces { .. }), "{err}");
}

#[test]
fn morton_order_walks_squares_within_squares() {
    let cells: Vec<(u64, u64)> = (0..8).map(morton_decode).collect();
    assert_eq!(cells, [(0, 0), (1, 0), (0, 1), (1, 1), (2, 0), (3, 0), (2, 1), (3, 1)]);
}

#[test]
fn morton_encode_undoes_decode() {
    for i in [0u64, 1, 2, 3, 77, 1023, 4096, 123_456, (1 << 30) - 1] {
        let (x, y) = morton_decode(i);
        assert_eq!(morton_encode(x as u32, y as u32), i);
    }
}

/// Frame after frame: faces whose lights stay keep their blocks and are not drawn again; a
/// moved light's faces are; with the cache off every face is; the layout is the same either
/// way, and the free space is whole again when every face has gone.
#[test]
fn kept_faces_keep_their_blocks_and_only_moved_lights_are_drawn() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let lights: Vec<(u32, PlannedLight)> = (0..200)
        .map(|i| {
            (
                i * 3,
                light(rng.random_range(-8.0..8.0), rng.random_range(0.0..4.0), rng.random_range(-10.0..5.0), rng.random_range(0.5..3.0)),
            )
        })
        .collect();
    let mut cached = ShadowAtlas::new(64 * MIB).unwrap();
    let mut uncached = cached.clone();
    let mut eye = Vec3::new(0.0, 2.0, 10.0);
    let mut moving = lights.clone();
    for frame in 0..20 {
        // The camera drifts (sizes and visible faces change now and then); every fifth
        // frame the first ten lights move.
        eye += Vec3::new(0.3, 0.0, -0.2);
        let c = Camera::looking_at(eye, Vec3::new(0.0, 2.0, 0.0), 60.0, 0.1, 100.0);
        if frame % 5 == 4 {
            for (_, l) in &mut moving[..10] {
                l.position.x += 0.25;
            }
        }
        let a = cached.plan(&moving, &c, (1920, 1080), None, true).unwrap();
        let b = uncached.plan(&moving, &c, (1920, 1080), None, false).unwrap();
        assert_packed(&a);
        let place = |p: &AtlasPlan| p.tiles.iter().map(|t| (t.light, t.face, t.size, t.base)).collect::<Vec<_>>();
        assert_eq!(place(&a), place(&b), "frame {frame}: the cache changed the layout");
        assert!(b.tiles.iter().all(|t| t.redraw));
        if frame > 0 {
            let moved = a.tiles.iter().filter(|t| t.redraw && t.light < 10).count();
            let others = a.redrawn() - moved;
            assert!(others < a.tiles.len() / 4, "frame {frame}: {others} of {} unmoved faces drawn again", a.tiles.len());
            if frame % 5 == 4 {
                assert!(a.tiles.iter().filter(|t| t.light < 10).all(|t| t.redraw), "frame {frame}: a moved light's face kept");
            }
        }
    }
    // A still camera and still lights: nothing is drawn again.
    let c = Camera::looking_at(eye, Vec3::new(0.0, 2.0, 0.0), 60.0, 0.1, 100.0);
    cached.plan(&moving, &c, (1920, 1080), None, true).unwrap();
    assert_eq!(cached.plan(&moving, &c, (1920, 1080), None, true).unwrap().redrawn(), 0);
    // No lights: every block is free again, merged back into the largest.
    assert!(cached.plan(&[], &c, (1920, 1080), None, true).unwrap().tiles.is_empty());
    let fresh = ShadowAtlas::new(64 * MIB).unwrap();
    assert_eq!(cached.free, fresh.free);
}
