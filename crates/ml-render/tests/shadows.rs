//! The blinn-phong sun's shadow (a shadow map with 3×3 PCF, docs/DESIGN.md#sun-shadow-map): a
//! ball above a floor, lit by the sun at 45°. Rendered with the ball (A), without it (B) and
//! with the sun off (C). Since the sun's light adds up, the sun's visibility at a floor pixel
//! is, in linear light, v = (A − C) / (B − C): 0 in the umbra, 1 in the open, a ramp across the
//! PCF edge.

mod common;

use glam::Vec3;
use ml_cpu::blinn_phong::{shadow_view_proj, BlinnPhongLights};
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_render::scene_textures::SHADOW_MAP_SIZE;
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
    let mut settings = RenderSettings::new(Technique::Forward, size, size);
    settings.shading = ShadingModel::BlinnPhong;
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
