//! The blinn-phong sun's shadow (a shadow map with 3×3 PCF, docs/DESIGN.md#sun-shadow-map): a
//! ball above a floor, lit by the sun at 45°. Rendered with the ball (A), without it (B) and
//! with the sun off (C). Since the sun's light adds up, the sun's visibility at a floor pixel
//! is, in linear light, v = (A − C) / (B − C): 0 in the umbra, 1 in the open, a ramp across the
//! PCF edge.

use crate::common;

use glam::Vec3;
use ml_cpu::blinn_phong::{shadow_view_proj, BlinnPhongLights};
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_render::SHADOW_MAP_SIZE;
use ml_render::{RenderOutput, RenderSettings, ShadingModel, Technique};

const BALL_CENTRE: Vec3 = Vec3::new(0.0, 2.0, 0.0);
const BALL_RADIUS: f32 = 0.5;

fn sun() -> Vec3 {
    Vec3::new(1.0, -1.0, 0.0).normalize()
}

/// The floor (and the ball), the sun at 45° towards +x, a dim ambient, no spot light and one
/// point light far away (a light buffer may not be empty).
fn scene(ball: bool, sun_on: bool, camera: Camera) -> Scene {
    let floor = Material { albedo: Vec3::splat(0.8), roughness: 0.9, metallic: 0.0 };
    let mut objects = vec![Object::placed(MeshKind::Plane, Vec3::ZERO, 4.0, floor)];
    // The ball stays in the scene's bounds either way, so the shadow map's texels are the same.
    let at = if ball { BALL_CENTRE } else { Vec3::new(0.0, -3.0, 0.0) };
    objects.push(Object::placed(MeshKind::Sphere, at, BALL_RADIUS, floor));
    let mut lights =
        BlinnPhongLights { sun_direction: sun(), sun_strength: Vec3::splat(if sun_on { 1.0 } else { 0.0 }), ..Default::default() };
    lights.spot.strength = Vec3::ZERO;
    lights.ambient = Vec3::splat(0.1);
    let far_light = PointLight { position_radius: [100.0, 100.0, 100.0, 0.1], color: [1.0; 4] };
    Scene { blinn_phong: lights, ..Scene::new(objects, vec![far_light], camera) }
}

fn render_abc(camera: Camera, size: u32) -> [RenderOutput; 3] {
    render_abc_with(camera, size, ml_render::SunShadowMode::Graphics)
}

fn render_abc_with(camera: Camera, size: u32, sun_shadow: ml_render::SunShadowMode) -> [RenderOutput; 3] {
    let mut settings = RenderSettings::new(Technique::Forward, size, size);
    settings.shading = ShadingModel::BlinnPhong;
    settings.sun_shadow = sun_shadow;
    [(true, true), (false, true), (true, false)].map(|(ball, sun_on)| common::render(scene(ball, sun_on, camera), settings))
}

fn linear(out: &RenderOutput, x: u32, y: u32) -> f32 {
    (common::pixel(out, x, y)[1] as f32 / 255.0).powf(2.2)
}

/// Where the pixel (x, y) sees the floor.
fn floor_point(camera: &Camera, x: u32, y: u32, size: u32) -> Vec3 {
    let (o, d) = camera.pixel_ray(x, y, size, size);
    o + d * (-o.y / d.y)
}

/// The pixel nearest to where the camera sees world point `p` (searched: the images are small).
fn pixel_of(camera: &Camera, p: Vec3, size: u32) -> (u32, u32) {
    (0..size * size)
        .map(|i| (i % size, i / size))
        .min_by(|a, b| {
            let da = floor_point(camera, a.0, a.1, size).distance(p);
            let db = floor_point(camera, b.0, b.1, size).distance(p);
            da.total_cmp(&db)
        })
        .unwrap()
}

#[test]
fn umbra_is_the_sunless_image_and_the_rest_is_unchanged() {
    const SIZE: u32 = 96;
    let camera = Camera::looking_at(Vec3::new(1.0, 7.0, 1.5), Vec3::new(1.0, 0.0, 0.0), 50.0, 0.1, 100.0);
    let [a, b, c] = render_abc(camera, SIZE);
    // The ball's shadow is centred where the sun's ray through its centre meets the floor.
    let umbra = BALL_CENTRE + sun() * (BALL_CENTRE.y / -sun().y);
    let (ux, uy) = pixel_of(&camera, umbra, SIZE);
    let (pa, pb, pc) = (common::pixel(&a, ux, uy), common::pixel(&b, ux, uy), common::pixel(&c, ux, uy));
    println!("umbra at {umbra}, pixel ({ux}, {uy}): with ball {pa:?}, without {pb:?}, sun off {pc:?}");
    for ch in 0..3 {
        assert!(pa[ch].abs_diff(pc[ch]) <= 1, "umbra: {pa:?} should be the sun-less {pc:?}");
        assert!((pb[ch] as f32 / 255.0).powf(2.2) > 2.0 * (pa[ch] as f32 / 255.0).powf(2.2), "umbra not darker: {pa:?} vs {pb:?}");
    }
    // Away from the shadow and the ball, the floor is exactly as without the ball.
    let mut compared = 0;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let p = floor_point(&camera, x, y, SIZE);
            let near_shadow = (p - umbra).length() < 1.5 || (p - Vec3::new(BALL_CENTRE.x, 0.0, BALL_CENTRE.z)).length() < 2.0;
            if !near_shadow && p.x.abs() < 4.0 && p.z.abs() < 4.0 {
                assert_eq!(common::pixel(&a, x, y), common::pixel(&b, x, y), "pixel ({x}, {y}) at {p} changed");
                compared += 1;
            }
        }
    }
    assert!(compared > 2000, "only {compared} pixels compared");
}

/// With `--sun-shadow rays` the shadow is hard and exact: at every floor pixel where a CPU ray
/// caster over every triangle is sure whether the sun's ray from the point is blocked, the
/// sun's visibility (A − C)/(B − C) is 0 where it is and 1 where not, within 1/255.
#[test]
fn sun_rays_cast_the_shadow_a_triangle_caster_says() {
    const SIZE: u32 = 96;
    let camera = Camera::looking_at(Vec3::new(1.0, 7.0, 1.5), Vec3::new(1.0, 0.0, 0.0), 50.0, 0.1, 100.0);
    let [a, b, c] = render_abc_with(camera, SIZE, ml_render::SunShadowMode::Rays);
    let with_ball = scene(true, true, camera);
    let world = ml_cpu::ray_bvh::WorldTriangles::new(&with_ball);
    let (mut shadowed, mut lit) = (0, 0);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let p = floor_point(&camera, x, y, SIZE);
            // The floor in view there (not the ball in front of it).
            let (o, d) = camera.pixel_ray(x, y, SIZE, SIZE);
            if p.x.abs() > 3.9 || p.z.abs() > 3.9 || world.first_hit(o, d).is_none_or(|(_, _, object)| object != 0) {
                continue;
            }
            let origin = p + Vec3::Y * 1e-4;
            let target = origin - sun() * 100.0;
            if !world.sure(origin, target, 2e-3, 1e-5) {
                continue;
            }
            let blocked = world.occluded(origin, target);
            let (pa, pb, pc) = (common::pixel(&a, x, y), common::pixel(&b, x, y), common::pixel(&c, x, y));
            let want = if blocked { pc } else { pb };
            assert!(
                pa.iter().zip(want).all(|(g, w)| g.abs_diff(w) <= 1),
                "pixel ({x}, {y}) at {p}: {pa:?}, want {want:?} (blocked: {blocked})"
            );
            if blocked {
                shadowed += 1;
            } else {
                lit += 1;
            }
        }
    }
    println!("sun rays: {shadowed} shadowed and {lit} lit floor pixels as the caster says");
    assert!(shadowed > 40 && lit > 2000, "{shadowed} shadowed, {lit} lit");
}

#[test]
fn pcf_softens_the_shadow_edge_over_a_few_texels() {
    const SIZE: u32 = 128;
    // The shadow's edge on the +x side: the ellipse's semi-axis along x is r·√2.
    let edge = Vec3::new(BALL_CENTRE.y + BALL_RADIUS * 2f32.sqrt(), 0.0, 0.0);
    let camera = Camera::looking_at(edge + Vec3::new(0.0, 2.0, 0.4), edge, 4.0, 0.1, 100.0);
    let [a, b, c] = render_abc(camera, SIZE);
    let y = SIZE / 2;
    let visibility: Vec<(f32, f32)> = (0..SIZE)
        .map(|x| {
            let (la, lb, lc) = (linear(&a, x, y), linear(&b, x, y), linear(&c, x, y));
            (floor_point(&camera, x, y, SIZE).x, (la - lc) / (lb - lc))
        })
        .collect();
    let first = |level: f32| visibility.iter().find(|(_, v)| *v >= level).map(|(x, _)| *x).expect("the edge is in view");
    let (x10, x90) = (first(0.1), first(0.9));
    assert!(visibility[0].1 < 0.05 && visibility[SIZE as usize - 1].1 > 0.95, "row should run from umbra to light");
    // One texel of the shadow map in world units (the same fit the renderer makes).
    let (lo, hi) = scene(true, true, camera).bounds();
    let texel = 2.0 / shadow_view_proj(lo, hi, sun()).row(0).truncate().length() / SHADOW_MAP_SIZE as f32;
    // Along x the sun's rays slant at 45°: one texel across the light is √2 texels on the floor.
    let width = (x90 - x10) / (texel * 2f32.sqrt());
    println!("10–90 % of the sun between x = {x10:.4} and {x90:.4}: {width:.2} shadow-map texels ({texel:.5} world units each)");
    assert!((1.0..=2.5).contains(&width), "penumbra of {width:.2} texels");
}

/// The compute shadow raster (`--sun-shadow compute`: one orthographic view) draws the map the
/// render pass draws: on the ball above the floor (a large floor, small sphere triangles), the
/// seed's teapots on a floor and the bench scene (hundreds of objects), every texel is covered
/// by both or neither, the depths agree up to where each raster puts the corners (ours snapped
/// to 1/256 texel, the driver's plane its own), and the images agree within 1/255 but for a
/// rare pixel whose PCF tap compares a lit surface with its own depth.
#[test]
fn the_compute_raster_draws_the_same_sun_shadow_map() {
    use ml_cpu::lights::LightParams;
    use ml_render::{Renderer, SunShadowMode};
    use ml_vk::{Context, ContextDesc};
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("a validated Vulkan device");
    let counter = ctx.validation_counter();
    let camera = Camera::looking_at(Vec3::new(1.0, 7.0, 1.5), Vec3::new(1.0, 0.0, 0.0), 50.0, 0.1, 100.0);
    let teapots = Scene::seed(MeshKind::Teapot, Material::named("copper").unwrap(), &LightParams::seed_default()).unwrap();
    let bench = ml_cpu::bench_scene::bench_scene(64, 1, ml_cpu::bench_scene::BENCH_OBJECTS).unwrap();
    for (name, scene) in [("ball", scene(true, true, camera)), ("teapots", teapots.with_floor()), ("bench", bench)] {
        let mut settings = RenderSettings::new(Technique::Forward, 96, 96);
        settings.shading = ShadingModel::BlinnPhong;
        let draw = |sun_shadow| {
            let mut renderer = Renderer::new(&ctx, scene.clone(), RenderSettings { sun_shadow, ..settings }).expect("renderer");
            let image = renderer.render().expect("render");
            (renderer.sun_shadow_depths().expect("shadow map read-back"), image)
        };
        let (graphics, graphics_image) = draw(SunShadowMode::Graphics);
        let (compute, compute_image) = draw(SunShadowMode::Compute);
        assert_eq!(graphics.len(), (SHADOW_MAP_SIZE * SHADOW_MAP_SIZE) as usize);
        let (coverage, differ) = common::coverage_difference(&graphics, &compute);
        let reached = common::reached;
        let worst = graphics.iter().zip(&compute).filter(|(g, _)| reached(**g)).map(|(g, c)| (g - c).abs()).fold(0.0, f32::max);
        let (max, pixels) = common::max_difference(&graphics_image, &compute_image);
        // Our depths come from the corners snapped to 1/256 texel, the render pass's from the
        // driver's own plane: at most the plane's change over 1/512 texel along each axis,
        // estimated from the render pass's map itself (a neighbour on another surface only
        // loosens it), plus float rounding.
        let side = SHADOW_MAP_SIZE as usize;
        let step = |i: usize, j: Option<usize>| j.map_or(0.0, |j| (graphics[i] - graphics[j]).abs());
        let snap_bound = |i: usize| {
            let (x, y) = (i % side, i / side);
            let sx = step(i, x.checked_sub(1).map(|x| y * side + x)).max(step(i, (x + 1 < side).then_some(i + 1)));
            let sy = step(i, y.checked_sub(1).map(|y| y * side + x)).max(step(i, (y + 1 < side).then_some(i + side)));
            (sx + sy) / 512.0 + 1e-6
        };
        let covered: Vec<usize> = (0..graphics.len()).filter(|&i| reached(graphics[i])).collect();
        let surfaces = covered.len();
        let past_bound = covered.iter().filter(|&&i| (graphics[i] - compute[i]).abs() > snap_bound(i)).count();
        // Slivers are steeper than their neighbours say; they are bounded by the depth of one
        // shadow-map texel along the sun (the shading's normal offset lifts a lookup by 1.5).
        let (lo, hi) = scene.bounds();
        let view_proj = shadow_view_proj(lo, hi, scene.blinn_phong.sun_direction);
        let texel_world = 2.0 / view_proj.row(0).truncate().length() / SHADOW_MAP_SIZE as f32;
        let texel_depth = texel_world * view_proj.row(2).truncate().length();
        let beyond = common::pixels_beyond(&graphics_image, &compute_image, 1);
        println!(
            "{name}: {surfaces} of {} texels hold a surface, {} covered by one raster only; {differ} differ, by at most {worst:e} ({:.3} of a texel's depth), {past_bound} by more than the snapping explains; images: max {max}/255 at {pixels} pixels, {beyond} beyond 1/255",
            graphics.len(),
            coverage.len(),
            worst / texel_depth,
        );
        assert!(surfaces > 100_000, "{name}: only {surfaces} texels hold a surface");
        assert!(
            coverage.is_empty(),
            "{name}: texels (index, graphics, compute) one raster covers: {:?}",
            &coverage[..coverage.len().min(12)]
        );
        // Measured: 0 (ball), 21 (teapots), 163 (bench) of ~10^6 texels past the snapping's
        // bound, the worst 0.06, 0.88 and 1.24 of a texel's depth.
        assert!(
            past_bound * 1000 <= covered.len(),
            "{name}: {past_bound} of {} texels differ by more than the snapping explains",
            covered.len()
        );
        assert!(worst <= 2.0 * texel_depth, "{name}: depths differ by {} of a texel's depth", worst / texel_depth);
        // A lit surface samples its own depth in the map (the normal offset lifts the lookup
        // by less than the surface's slope across a PCF tap), so a tap whose comparison sits
        // within the rounding of equality may flip: one pixel of the ball's 9,216 measured
        // (6/255, where the ball's top faces the sun at n·l = 0.46). At most one pixel in a
        // thousand.
        let total = (graphics_image.width * graphics_image.height) as usize;
        assert!(beyond * 1000 <= total, "{name}: {beyond} pixels differ by more than 1/255 (max {max}/255)");
    }
    drop(ctx);
    assert_eq!(counter.load(std::sync::atomic::Ordering::SeqCst), 0, "validation messages (printed above)");
}
