//! What the viewer (docs/usage.md#view-the-window) changes in a live renderer: a new size,
//! cluster grid and debug view (new targets, frame slots, clustered-gpu builder, tone map), new
//! lights (light buffers, frame slots, builder) and new objects (meshes, object buffer) must
//! give exactly the image a renderer made for them from the start gives — in every technique,
//! with validation on — and moving the camera must match a renderer made at that camera.

use crate::common;
use crate::common::view;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::cluster::ClusterDims;
use ml_cpu::lights::{LightLayout, LightParams, RadiusRange};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_render::{RenderSettings, Renderer, ShadingModel, Technique};

fn seed_scene(lights: &LightParams) -> Scene {
    Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), lights).unwrap()
}

#[test]
fn resized_relit_and_moved_renderers_equal_fresh_ones() {
    let ctx = common::pooled_context();
    let many = LightParams { count: 700, layout: LightLayout::Random, seed: 5, radius: RadiusRange { min: 1.0, max: 6.0 } };
    let camera = Camera::looking_at(Vec3::new(-6.0, 9.0, 12.0), Vec3::ZERO, 50.0, 0.1, 200.0);
    for technique in Technique::ALL {
        let settings = |w, h| RenderSettings { frames: 2, ..RenderSettings::new(technique, w, h) };
        let mut live = Renderer::new(&ctx, seed_scene(&LightParams::seed_default()), settings(96, 64)).expect("renderer");
        live.render().expect("render");
        let mut resized = RenderSettings { clusters: ClusterDims { x: 8, y: 6, z: 12 }, ..settings(120, 80) };
        assert!(live.reconfigure(resized).expect("resize"), "a new size and grid keep the pipelines");
        resized.clusters = ClusterDims::DEFAULT;
        assert!(live.reconfigure(resized).expect("the grid back"));
        assert!(
            !live.reconfigure(RenderSettings { shading: ShadingModel::Pbr, ..resized }).expect("a new model"),
            "a new model needs new pipelines"
        );
        // A debug view and back (the subpass techniques swap their tone map).
        let depth_view = RenderSettings { debug_view: view("depth"), ..resized };
        assert!(live.reconfigure(depth_view).expect("a debug view"));
        let depth = live.render().expect("render the depth view");
        let fresh_depth = Renderer::new(&ctx, seed_scene(&LightParams::seed_default()), depth_view).and_then(|mut r| r.render()).unwrap();
        assert_eq!(common::max_difference(&depth, &fresh_depth).0, 0, "{}: the depth view after reconfigure", technique.name());
        assert!(live.reconfigure(resized).expect("no debug view"));
        live.set_lights(many.build().unwrap()).expect("new lights");
        // The seed's "Type" and "Material" combos: teapots of copper.
        let teapots = Scene::seed(MeshKind::Teapot, Material::named("copper").unwrap(), &many).unwrap();
        assert!(live.set_objects(&teapots).expect("new objects"));
        let changed = live.render().expect("render after the changes");
        live.set_camera(camera).expect("move");
        let moved = live.render().expect("render after moving");
        drop(live);
        let fresh = |camera: Option<Camera>| {
            let mut scene = teapots.clone();
            if let Some(c) = camera {
                scene.camera = c;
            }
            Renderer::new(&ctx, scene, settings(120, 80)).and_then(|mut r| r.render()).expect("fresh render")
        };
        let fresh_changed = fresh(None);
        // The context's pipelines are shared: the same settings again make none.
        let kept = ctx.pipeline_counts().0;
        let fresh_moved = fresh(Some(camera));
        assert_eq!(ctx.pipeline_counts().0, kept, "{}: a renderer made again made new pipelines", technique.name());
        for (what, live, fresh) in [("resized and relit", &changed, &fresh_changed), ("moved", &moved, &fresh_moved)] {
            assert_eq!((live.width, live.height), (120, 80));
            let (max, differing) = common::max_difference(live, fresh);
            assert_eq!(max, 0, "{}: {what} differs from a fresh renderer by {max}/255 at {differing} pixels", technique.name());
        }
        // The new lights show: the image is not the one the old lights give.
        let old_lights =
            Renderer::new(&ctx, seed_scene(&LightParams::seed_default()), settings(120, 80)).and_then(|mut r| r.render()).unwrap();
        let (max, _) = common::max_difference(&changed, &old_lights);
        assert!(max > 30, "{}: the new lights changed the image by only {max}/255", technique.name());
    }
    // Objects whose materials have lobes (pbr) need pipelines made for them: refused, nothing
    // changed, where the renderer was made without.
    let pbr = RenderSettings { shading: ShadingModel::Pbr, ..RenderSettings::new(Technique::Visibility, 64, 48) };
    let mut plain = Renderer::new(&ctx, seed_scene(&LightParams::seed_default()), pbr).expect("renderer");
    let mut coated = seed_scene(&LightParams::seed_default());
    coated.objects[0].extras.lobes.clearcoat = 1.0;
    assert!(!plain.set_objects(&coated).expect("asked"), "objects with lobes set on a renderer made without");
    drop(plain);
    assert_eq!(ctx.pipeline_counts().1, 0, "every renderer is gone but pipelines are still held");
}
