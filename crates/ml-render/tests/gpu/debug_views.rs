//! The G-buffer, depth and shadow-map debug views: each shows what it promises, and the
//! surface views are the same whichever technique draws them (forward computes the values
//! the deferred paths read from their G-buffer).

use crate::common;
use crate::common::view;

use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_render::{DebugView, RenderOutput, RenderSettings, Renderer, ShadingModel, Technique};
use ml_vk::{Context, ContextDesc};

const W: u32 = 160;
const H: u32 = 90;

fn seed_scene(object: MeshKind) -> Scene {
    Scene::seed(object, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap()
}

fn render(scene: &Scene, technique: Technique, shading: ShadingModel, view: DebugView) -> RenderOutput {
    let mut s = RenderSettings::new(technique, W, H);
    s.shading = shading;
    s.debug_view = view;
    common::render(scene.clone(), s)
}

/// Covered pixels (not the background colour).
fn covered(out: &RenderOutput) -> Vec<[u8; 3]> {
    out.rgba.chunks_exact(4).map(|p| [p[0], p[1], p[2]]).filter(|p| *p != [5, 5, 5]).collect()
}

#[test]
fn surface_views_are_the_same_in_every_technique() {
    let scene = seed_scene(MeshKind::Teapot).with_floor();
    for view in [view("gbuffer-albedo"), view("gbuffer-normal"), view("gbuffer-material"), view("depth")] {
        let forward = render(&scene, Technique::Forward, ShadingModel::BlinnPhong, view);
        for t in [Technique::ClusteredCpu, Technique::Deferred, Technique::DeferredClustered, Technique::DeferredCompute] {
            let (worst, _) = common::max_difference(&forward, &render(&scene, t, ShadingModel::BlinnPhong, view));
            assert!(worst <= 1, "{}: {} differs from forward by {worst}/255", view.name(), t.name());
        }
    }
}

#[test]
fn surface_views_show_albedo_normal_material_and_depth() {
    let spheres = seed_scene(MeshKind::Sphere);
    // Gold's albedo (1, 0.766, 0.336) after the output's gamma: (255, 226, 155).
    let albedo = covered(&render(&spheres, Technique::Deferred, ShadingModel::Seed, view("gbuffer-albedo")));
    assert!(
        albedo.len() > 1000 && albedo.iter().all(|p| p[0] == 255 && p[1].abs_diff(226) <= 1 && p[2].abs_diff(155) <= 1),
        "{:?}",
        albedo[0]
    );
    // Roughness 0.1, metallic 1: (26, 255, 0).
    let material = covered(&render(&spheres, Technique::Forward, ShadingModel::Seed, view("gbuffer-material")));
    assert!(material.iter().all(|p| p[0].abs_diff(26) <= 1 && p[1] == 255 && p[2] == 0), "{:?}", material[0]);
    // Planes face +Y: (0.5, 1, 0.5).
    let planes = seed_scene(MeshKind::Plane);
    let normal = covered(&render(&planes, Technique::DeferredCompute, ShadingModel::Seed, view("gbuffer-normal")));
    assert!(
        normal.len() > 1000 && normal.iter().all(|p| p[0].abs_diff(128) <= 1 && p[1] == 255 && p[2].abs_diff(128) <= 1),
        "{:?}",
        normal[0]
    );
    // Depth grows up the image (the camera looks down at the grid from its near side).
    let depth = render(&planes, Technique::Forward, ShadingModel::Seed, view("depth"));
    let column = |y: u32| common::pixel(&depth, W / 2, y)[0];
    let (near, far) = (column(H - 12), column(12));
    assert!(far > near + 3 && near > 5, "far {far} should be lighter than near {near}");
}

#[test]
fn shadow_map_view_paints_the_map_and_needs_shadows() {
    let scene = seed_scene(MeshKind::Sphere).with_floor();
    let map = render(&scene, Technique::Forward, ShadingModel::BlinnPhong, view("shadow-map"));
    let mut greys: Vec<u8> = map.rgba.chunks_exact(4).map(|p| p[0]).collect();
    greys.sort_unstable();
    greys.dedup();
    // Black where the map is empty, many greys where the floor and the spheres are.
    assert!(greys[0] == 0 && greys.len() > 20, "{} grey levels", greys.len());
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("device");
    let mut settings = RenderSettings::new(Technique::Forward, W, H);
    settings.debug_view = view("shadow-map");
    let err = Renderer::new(&ctx, scene, settings).err().expect("the seed model has no shadow map").to_string();
    assert!(err.contains("blinn-phong"), "{err}");
}
