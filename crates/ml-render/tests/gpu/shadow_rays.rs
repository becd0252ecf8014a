//! Shadow rays (`--omni-shadow rays`, docs/DESIGN.md#shadow-rays) in the image. A light's
//! contribution adds up, so at a pixel where a CPU ray caster over every triangle of the
//! scene is sure which lights the surface sees, the image with every light shadowed by rays
//! must equal the shadow-less render with only those lights on (within 1/255). "Sure": the
//! pixel's corners see the same flat surface, and each segment from the point to a light
//! misses or crosses every triangle by a margin (the GPU's point and normal differ from the
//! CPU's by rounding). And every technique gives the image the brute-force forward pass gives,
//! but for a counted few pixels on shadow edges, where the techniques' points (interpolated
//! or rebuilt from depth) fall on either side. Against the shadow cubes and the atlas, rays
//! shadow the same pixels wherever an analytic ray test is sure of each light by a margin of
//! the cubes' texels.

use crate::common;
use crate::common::view;

use glam::Vec3;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::lights::motion_offset;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::ray_bvh::WorldTriangles;
use ml_cpu::scene::{Object, Scene};
use ml_render::{
    Antialiasing, AntialiasingStats, OmniShadowMode, OmniShadowSettings, RenderOutput, RenderSettings, ShadingModel, Technique,
};
use rand::{Rng, SeedableRng};
use rayon::prelude::*;

const SIZE: u32 = 96;
/// Margin of a sure segment beside a triangle's edges (barycentric units).
const MARGIN: f32 = 2e-3;

fn settings(technique: Technique, rays: bool, lights: u32) -> RenderSettings {
    let mut s = RenderSettings::new(technique, SIZE, SIZE);
    s.shading = ShadingModel::Pbr;
    s.omni = rays.then_some(OmniShadowSettings { mode: OmniShadowMode::Rays, lights, all: true, size: 1 });
    s
}

/// The scene with only the lights in `on` lit (the rest black), no shadows: its point lights,
/// then its directional lights.
fn with_lights(scene: &Scene, on: &[bool]) -> Scene {
    let mut s = scene.clone();
    for (l, &lit) in s.lights.iter_mut().zip(on) {
        if !lit {
            l.color = [0.0; 4];
        }
    }
    for (d, &lit) in s.directional.iter_mut().zip(&on[scene.lights.len()..]) {
        if !lit {
            d.color = Vec3::ZERO;
        }
    }
    s
}

/// A pixel and, for each light that may light its point, (the light, whether it does).
type SurePixel = ((u32, u32), Vec<(usize, bool)>);

/// A reference render: each light's state (None: either) and the pixels it serves.
type Reference = (Vec<Option<bool>>, Vec<(u32, u32)>);

/// Per pixel where the triangle caster is sure which lights see the surface: for each light
/// that may light it (its point within the radius, not behind the surface: the others add
/// nothing, shadowed or not), whether it does.
fn sure_pixels(scene: &Scene, world: &WorldTriangles) -> Vec<SurePixel> {
    let pixels: Vec<(u32, u32)> = (0..SIZE * SIZE).map(|i| (i % SIZE, i / SIZE)).collect();
    pixels
        .into_par_iter()
        .filter_map(|(x, y)| {
            let hit = |dx: f32, dy: f32| {
                let (o, d) = common::shadow_rays::ray(&scene.camera, x as f32 + 0.5 + dx, y as f32 + 0.5 + dy, SIZE);
                world.first_hit(o, d).map(|(t, n, object)| (o + d * t, n, object))
            };
            let (point, normal, object) = hit(0.0, 0.0)?;
            // Its corners on the same flat surface of the same object (off silhouettes and
            // the edges of cut-outs).
            let corners = [(-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)];
            if !corners.iter().all(|&(dx, dy)| hit(dx, dy).is_some_and(|(_, n, o)| o == object && n.dot(normal) > 0.9999)) {
                return None;
            }
            // The shaders' origin (omni_shadow.glsl RAY_NORMAL_OFFSET); its own surface lies
            // that far behind it, a tenth of which the GPU's point may differ by.
            let offset = 1e-4 * point.abs().max_element().max(1.0);
            let origin = point + normal * offset;
            let mut seen = Vec::new();
            // Where the frame (time 0 of the lights' animation) has each light; a directional
            // one where the shaders put it, 10 km up its rays (lighting.glsl SUM_DIRECTIONAL).
            let points = scene
                .lights
                .iter()
                .map(|l| (Vec3::from_slice(&l.position_radius[..3]) + motion_offset(0.0, scene.light_motion), l.position_radius[3]));
            let far = scene.directional.iter().map(|d| (point - d.direction * 1e4, f32::INFINITY));
            for (i, (light, radius)) in points.chain(far).enumerate() {
                let to_light = light - point;
                if to_light.length() >= radius || to_light.normalize().dot(normal) < -0.05 {
                    continue;
                }
                if !world.sure(origin, light, MARGIN, offset * 0.1) {
                    return None;
                }
                seen.push((i, !world.occluded(origin, light)));
            }
            Some(((x, y), seen))
        })
        .collect()
}

/// Render `scene` with every light shadowed by rays and compare every sure pixel with a
/// shadow-less render where the lights it sees are on and those shadowed off. One such render
/// serves every pixel that asks nothing of it the others contradict (lights are local: a few
/// renders serve them all). Returns (pixels checked, of them in some light's shadow).
fn ray_test(name: &str, scene: &Scene) -> (usize, usize) {
    let n = scene.lights.len() as u32;
    let shadowed = common::render(scene.clone(), settings(Technique::Forward, true, n));
    let world = WorldTriangles::new(scene);
    let mut references: Vec<Reference> = Vec::new();
    let (mut checked, mut in_shadow) = (0, 0);
    for (p, seen) in sure_pixels(scene, &world) {
        let fits = |states: &[Option<bool>]| seen.iter().all(|&(i, lit)| states[i].is_none_or(|s| s == lit));
        let r = match references.iter().position(|(states, _)| fits(states)) {
            Some(r) => r,
            None => {
                references.push((vec![None; scene.lights.len() + scene.directional.len()], Vec::new()));
                references.len() - 1
            }
        };
        for &(i, lit) in &seen {
            references[r].0[i] = Some(lit);
        }
        references[r].1.push(p);
        checked += 1;
        in_shadow += usize::from(seen.iter().any(|&(_, lit)| !lit));
    }
    let mut wrong = Vec::new();
    for (states, pixels) in &references {
        let on: Vec<bool> = states.iter().map(|s| s.unwrap_or(true)).collect();
        let reference = common::render(with_lights(scene, &on), settings(Technique::Forward, false, n));
        for &(x, y) in pixels {
            let (got, want) = (common::pixel(&shadowed, x, y), common::pixel(&reference, x, y));
            if got.iter().zip(want).any(|(a, b)| a.abs_diff(b) > 1) {
                wrong.push(((x, y), got, want));
            }
        }
    }
    println!(
        "{name}: {checked} sure pixels, {in_shadow} in some light's shadow, {} reference renders, {} wrong",
        references.len(),
        wrong.len()
    );
    assert!(
        wrong.is_empty(),
        "{name}: pixels that disagree with the triangle caster (pixel, rendered, expected): {:?}",
        &wrong[..wrong.len().min(12)]
    );
    (checked, in_shadow)
}

/// The shadow room (a closed room, a pillar of three cubes, one light).
#[test]
fn one_light_shadows_where_the_triangle_caster_says() {
    let (checked, in_shadow) = ray_test("room, 1 light", &Scene::shadow_room());
    assert!(checked > 4000 && in_shadow > 150, "{checked} checked, {in_shadow} in shadow");
}

/// The room with rotated occluders of every kind of mesh, 32 small blocks and 256 lights of
/// 1.5–3.5 m: each point is within reach of a few, each shadowed by its own occluders.
#[test]
fn two_hundred_and_fifty_six_lights_shadow_where_the_triangle_caster_says() {
    let mut scene = cluttered_room(256, 11);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
    for l in &mut scene.lights {
        l.position_radius[3] = rng.random_range(1.5..3.5);
    }
    // And 32 small rotated blocks among the lights.
    let grey = Material { albedo: Vec3::splat(0.6), roughness: 0.8, metallic: 0.0 };
    for _ in 0..32 {
        let at = Vec3::new(rng.random_range(-4.0..4.0), rng.random_range(-4.5..3.0), rng.random_range(-4.0..4.0));
        let rotation = glam::Quat::from_euler(glam::EulerRot::XYZ, rng.random_range(0.0..6.3), rng.random_range(0.0..6.3), 0.0);
        let scale = Vec3::new(rng.random_range(0.1..0.6), rng.random_range(0.1..0.6), rng.random_range(0.1..0.6));
        let transform = glam::Mat4::from_scale_rotation_translation(scale, rotation, at);
        scene.objects.push(Object { transform, ..Object::placed(MeshKind::Cube, Vec3::ZERO, 1.0, grey) });
    }
    let (checked, in_shadow) = ray_test("room, 256 lights", &scene);
    assert!(checked > 2000 && in_shadow > 500, "{checked} checked, {in_shadow} in shadow");
}

/// Directional lights cast their shadows through rays too: occluders of every kind over a
/// floor under three suns of different colours and slopes, with four point lights among them
/// and alone.
#[test]
fn directional_lights_shadow_where_the_triangle_caster_says() {
    let mut scene = suns_over_a_floor();
    let (checked, in_shadow) = ray_test("floor, 3 directional and 4 point lights", &scene);
    assert!(checked > 2000 && in_shadow > 500, "{checked} checked, {in_shadow} in shadow");
    // Suns alone (a glTF file's usual lighting) cast theirs with no point light at all.
    scene.lights.clear();
    let (checked, in_shadow) = ray_test("floor, 3 directional lights alone", &scene);
    assert!(checked > 2000 && in_shadow > 300, "{checked} checked, {in_shadow} in shadow");
}

/// Occluders of every kind over a floor under three suns of different colours and slopes,
/// with four point lights among them.
fn suns_over_a_floor() -> Scene {
    let mut scene = cluttered_room(4, 21);
    // The occluders alone (the last five) over a floor: the room's walls and ceiling would
    // shadow every sun everywhere.
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    scene.objects = scene.objects.split_off(scene.objects.len() - 5);
    scene.objects.push(Object::placed(MeshKind::Plane, Vec3::new(0.0, -5.0, 0.0), 7.0, grey));
    scene.directional = [(Vec3::new(0.3, -1.0, 0.2), Vec3::new(1.0, 0.9, 0.7)), (Vec3::new(-0.8, -0.6, 0.1), Vec3::new(0.3, 0.4, 0.9))]
        .into_iter()
        .chain([(Vec3::new(0.1, -0.5, -0.9), Vec3::new(0.2, 0.6, 0.2))])
        .map(|(d, color)| ml_cpu::scene::DirectionalLight { direction: d.normalize(), color })
        .collect();
    scene
}

/// Under the point-light shadow maps (the cube array, the atlas), whose cubes and tiles cannot
/// hold a light 10 km away, directional lights cast their shadows by rays: with the point
/// lights dark, the maps' images are the rays' image (which the test above holds to the
/// triangle caster), and differ from the image without shadows.
#[test]
fn directional_lights_cast_their_shadows_in_every_shadow_mode() {
    let scene = suns_over_a_floor();
    let mut on = vec![false; scene.lights.len()];
    on.extend(vec![true; scene.directional.len()]);
    let suns = with_lights(&scene, &on);
    let n = scene.lights.len() as u32;
    let maps = |mode: OmniShadowMode| {
        let mut s = settings(Technique::Forward, false, n);
        s.omni = Some(OmniShadowSettings { mode, lights: n, all: false, size: 64 });
        s
    };
    let atlas = OmniShadowMode::Atlas(ml_render::settings::AtlasSettings { budget_mib: 64, cache: true, fixed_size: Some(64) });
    let modes = [settings(Technique::Forward, true, n), maps(OmniShadowMode::COMPUTE), maps(OmniShadowMode::Direct), maps(atlas)];
    let outputs = common::render_each(&suns, &modes);
    let unshadowed = common::render(suns.clone(), settings(Technique::Forward, false, n));
    let shadowed = common::pixels_beyond(&outputs[0], &unshadowed, 8);
    println!("the suns' shadows: {shadowed} pixels");
    assert!(shadowed > 300, "the suns cast shadows on {shadowed} pixels only");
    for (name, other) in ["cube array (compute)", "cube array (direct)", "atlas"].iter().zip(&outputs[1..]) {
        let (worst, differing) = common::max_difference(&outputs[0], other);
        println!("rays against the {name}: {differing} pixels differ, by up to {worst}/255");
        assert!(worst <= 1, "{name}: the suns' shadows differ from the rays' by {worst}/255");
    }
}

/// The room with rotated occluders of every kind of mesh and 16 lights of random colours.
#[test]
fn sixteen_lights_shadow_where_the_triangle_caster_says() {
    let scene = cluttered_room(16, 3);
    let (checked, in_shadow) = ray_test("room, 16 lights", &scene);
    assert!(checked > 2000 && in_shadow > 500, "{checked} checked, {in_shadow} in shadow");
}

fn cluttered_room(lights: usize, seed: u64) -> Scene {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut scene = Scene::shadow_room();
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    for kind in [MeshKind::Sphere, MeshKind::Teapot, MeshKind::TorusKnot, MeshKind::Cube, MeshKind::Disc] {
        let at = Vec3::new(rng.random_range(-3.0..3.0), rng.random_range(-3.5..2.0), rng.random_range(-3.0..3.0));
        let rotation = glam::Quat::from_euler(glam::EulerRot::XYZ, rng.random_range(0.0..6.3), rng.random_range(0.0..6.3), 0.0);
        let transform = glam::Mat4::from_scale_rotation_translation(Vec3::splat(rng.random_range(0.4..0.9)), rotation, at);
        scene.objects.push(Object { transform, ..Object::placed(kind, Vec3::ZERO, 1.0, grey) });
    }
    scene.lights = (0..lights)
        .map(|_| {
            let at = Vec3::new(rng.random_range(-4.0..4.0), rng.random_range(-4.0..4.0), rng.random_range(-4.0..4.0));
            let c = [rng.random_range(0.1..1.0), rng.random_range(0.1..1.0), rng.random_range(0.1..1.0)];
            PointLight { position_radius: [at.x, at.y, at.z, rng.random_range(4.0..12.0)], color: [c[0], c[1], c[2], 0.0] }
        })
        .collect();
    scene
}

/// Every technique lights the cluttered room with 16 shadowed lights as the forward pass does,
/// but for the few pixels on a shadow's edge.
#[test]
fn every_technique_gives_the_forward_image() {
    let scene = cluttered_room(16, 5);
    let outputs = common::render_each(&scene, &Technique::ALL.map(|t| settings(t, true, 16)));
    let forward = &outputs[Technique::ALL.iter().position(|&t| t == Technique::Forward).unwrap()];
    for (t, out) in Technique::ALL.iter().zip(&outputs) {
        let edges = common::pixels_beyond(out, forward, 1);
        println!("{}: {edges} pixels beyond 1/255 of forward", t.name());
        assert!(edges <= (SIZE * SIZE / 200) as usize, "{}: {edges} pixels beyond 1/255", t.name());
    }
}

/// A grate between the light and the floor: a plane whose alpha texture cuts it into
/// stripes (bilinear, repeated four times) casts striped shadows — the rays read its mask at
/// each crossing as the raster reads it at each fragment.
#[test]
fn alpha_masked_surfaces_cast_the_shadows_their_masks_cut() {
    let mut scene = Scene::shadow_room();
    // Stripes across u: alpha 255 for four texels, 0 for four.
    let rgba: Vec<u8> = (0..8 * 8).flat_map(|i| [200, 200, 200, if (i % 8) < 4 { 255 } else { 0 }]).collect();
    scene.textures.push(ml_cpu::textures::TextureImage { width: 8, height: 8, rgba: rgba.into(), srgb: true, sampler: Default::default() });
    let grey = Material { albedo: Vec3::splat(0.7), roughness: 0.7, metallic: 0.0 };
    let transform = glam::Mat4::from_scale_rotation_translation(
        Vec3::new(1.6, 1.0, 1.6),
        glam::Quat::from_rotation_y(0.4),
        Vec3::new(-1.0, -3.6, -0.5),
    );
    let mut grate = Object { transform, ..Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, grey) };
    grate.textures.base_color = Some(0);
    grate.extras.alpha_mode = ml_cpu::scene::AlphaMode::Mask { cutoff: 0.5 };
    grate.extras.double_sided = true;
    grate.extras.uv_transform = glam::Affine2::from_scale(glam::Vec2::splat(4.0));
    scene.objects.push(grate);
    let (checked, in_shadow) = ray_test("room with a grate", &scene);
    assert!(checked > 3000 && in_shadow > 300, "{checked} checked, {in_shadow} in shadow");
}

/// The ray-cost view shows heat wherever a point traces a shadow ray (in every technique at
/// the same pixels), and none where no light reaches: the room's light shrunk to reach no
/// surface.
#[test]
fn the_ray_cost_view_shows_where_rays_are_traced() {
    let scene = Scene::shadow_room();
    let view = |technique| RenderSettings { debug_view: view("ray-cost"), ..settings(technique, true, 1) };
    let outputs = common::render_each(&scene, &[view(Technique::Forward), view(Technique::Visibility), view(Technique::DeferredCompute)]);
    let lit = |out: &RenderOutput| out.rgba.chunks_exact(4).filter(|p| p[..3] != [0, 0, 0]).count();
    let traced = lit(&outputs[0]);
    assert!(traced > (SIZE * SIZE / 2) as usize, "{traced} pixels with heat");
    // The same pixels trace rays in every technique (their counts may differ by a step where a
    // point rebuilt from depth falls on the other side of a box's face).
    for out in &outputs[1..] {
        assert_eq!(lit(out), traced);
    }
    let mut dark = scene.clone();
    dark.lights[0].position_radius[3] = 0.01;
    let none = common::render(dark, view(Technique::Forward));
    assert_eq!(lit(&none), 0, "no ray, no heat");
}

/// Against the shadow maps: in the shadow room with two more, coloured lights near the pillar
/// (whose shadows cross the floor and the walls in view), rays give the
/// image of the cube array (compute raster, 128² faces) and of the atlas at that size wherever
/// the analytic ray test is sure of each light — lit or shadowed by a margin of the cubes'
/// texels, so that their filtered edges lie elsewhere; the pixels that differ (the maps' edges)
/// are counted and few. One of the lights is a spot.
#[test]
fn rays_classify_as_the_cube_array_and_the_atlas_where_the_ray_test_is_sure() {
    const CUBE: u32 = 128;
    let mut scene = Scene::shadow_room();
    scene.lights.push(PointLight { position_radius: [3.0, -3.5, 1.5, 20.0], color: [1.0, 2.0, 3.0, 0.0] });
    scene.lights.push(PointLight { position_radius: [-0.5, -4.0, 0.5, 20.0], color: [3.0, 1.5, 0.5, 0.0] });
    // The last a spot (glTF's spot lights: a cone over a point light) aimed across the floor
    // past the pillar: its shadow is the point light's, in every mode.
    let spot = ml_cpu::gpu_types::LightCone::spot(Vec3::new(1.0, -0.3, 0.3).normalize(), 0.5, 1.2);
    scene.cones = vec![ml_cpu::gpu_types::LightCone::NONE, ml_cpu::gpu_types::LightCone::NONE, spot];
    let sure = common::shadow_rays::sure_pixels(&scene, SIZE, CUBE);
    let shadowed = sure.iter().filter(|(_, lit)| lit.iter().any(|&l| !l)).count();
    assert!(sure.len() > 3000 && shadowed > 300, "{} sure pixels, {shadowed} shadowed from some light", sure.len());
    let maps = |mode: OmniShadowMode| {
        let mut s = settings(Technique::Forward, false, 3);
        s.omni = Some(OmniShadowSettings { mode, lights: 3, all: false, size: CUBE });
        s
    };
    let atlas = OmniShadowMode::Atlas(ml_render::settings::AtlasSettings { budget_mib: 256, cache: true, fixed_size: Some(CUBE) });
    let outputs = common::render_each(&scene, &[settings(Technique::Forward, true, 3), maps(OmniShadowMode::COMPUTE), maps(atlas)]);
    let rays = &outputs[0];
    for (name, other) in [("cube array", &outputs[1]), ("atlas", &outputs[2])] {
        let wrong: Vec<(u32, u32)> = sure
            .iter()
            .map(|&(p, _)| p)
            .filter(|&(x, y)| common::pixel(rays, x, y).iter().zip(common::pixel(other, x, y)).any(|(a, b)| a.abs_diff(b) > 1))
            .collect();
        let beyond = common::pixels_beyond(rays, other, 1);
        println!("rays against the {name}: {beyond} of {} pixels > 1/255 apart, none of the {} sure", SIZE * SIZE, sure.len());
        assert!(wrong.is_empty(), "{name}: sure pixels differ: {:?}", &wrong[..wrong.len().min(12)]);
        assert!(beyond * 16 <= (SIZE * SIZE) as usize, "{name}: {beyond} pixels differ");
    }
}

/// The rays a compute lighting traces are counted (`--light-stats`), exactly: one for each
/// pixel and light whose contribution is not zero — as many as a CPU ray caster finds pixels
/// whose surface faces the light within its radius (but for a few pixels on silhouettes and
/// where N·L is within rounding of 0), twice as many with the light doubled, the same in
/// `visibility` and `deferred-compute`; without the statistics none are reported.
#[test]
fn the_rays_traced_are_counted() {
    let room = Scene::shadow_room();
    let mut doubled = room.clone();
    doubled.lights.push(doubled.lights[0]);
    let traced = |scene: &Scene, technique: Technique, light_stats: bool| {
        let s = RenderSettings { light_stats, ..settings(technique, true, scene.lights.len() as u32) };
        let out = common::render_each(scene, &[s]);
        out[0].stats.feature::<ml_render::RayStats>().expect("the hierarchy's row").traced
    };
    let once = traced(&room, Technique::Visibility, true).expect("visibility counts");
    assert_eq!(traced(&doubled, Technique::Visibility, true), Some(2 * once), "two lights at one place: twice the rays");
    let deferred = traced(&room, Technique::DeferredCompute, true).expect("deferred-compute counts");
    assert!(deferred.abs_diff(once) * 200 <= once, "visibility {once}, deferred-compute {deferred}");
    assert_eq!(traced(&room, Technique::Visibility, false), None);
    // The CPU's count: pixels whose nearest surface faces the light, within its radius.
    let world = WorldTriangles::new(&room);
    let l = room.lights[0].position_radius;
    let light = Vec3::new(l[0], l[1], l[2]);
    let expected = (0..SIZE * SIZE)
        .into_par_iter()
        .filter(|i| {
            let (o, d) = common::shadow_rays::ray(&room.camera, (i % SIZE) as f32 + 0.5, (i / SIZE) as f32 + 0.5, SIZE);
            world.first_hit(o, d).is_some_and(|(t, n, _)| {
                let to_light = light - (o + d * t);
                to_light.length() < l[3] && n.dot(to_light) > 0.0
            })
        })
        .count() as u64;
    println!("rays traced: {once} (CPU: {expected} pixels facing the light); deferred-compute {deferred}");
    assert!(expected > 5000 && once.abs_diff(expected) * 100 <= expected, "GPU {once}, CPU {expected}");
    // Anti-aliased, a pixel shades each surface its samples hold, at most a ray each from the
    // room's one light: a lane that shades several surfaces (an edge pixel's, dealt out)
    // counts each surface's rays once, not again with the next surface's.
    let s = RenderSettings { light_stats: true, antialiasing: Antialiasing::X4, ..settings(Technique::Visibility, true, 1) };
    let out = common::render_each(&room, &[s]);
    let rays = out[0].stats.feature::<ml_render::RayStats>().and_then(|r| r.traced).expect("visibility counts");
    let surfaces = out[0].stats.feature::<AntialiasingStats>().and_then(|a| a.surfaces).expect("the surfaces shaded");
    println!("anti-aliased: {rays} rays traced, {surfaces} surfaces shaded");
    assert!(surfaces > SIZE as u64 * SIZE as u64 / 2 && rays <= surfaces && rays * 10 >= surfaces * 5, "{rays} rays, {surfaces} surfaces");
}
