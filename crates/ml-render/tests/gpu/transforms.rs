//! Objects with any affine transform (glTF nodes turn and scale unevenly): an ellipsoid — the
//! unit sphere scaled by (2, 1, 0.5), turned and moved — shows, in the normal debug view of
//! every technique, the normals of the analytic ellipsoid where a CPU ray meets it (normals go
//! through the inverse transpose; a model-matrix normal would tilt visibly).

use crate::common;
use crate::common::view;

use glam::{Mat3, Mat4, Quat, Vec3};
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{Object, Scene};
use ml_render::{RenderSettings, Technique};

const SIZE: u32 = 96;

fn transform() -> Mat4 {
    Mat4::from_scale_rotation_translation(
        Vec3::new(2.0, 1.0, 0.5),
        Quat::from_euler(glam::EulerRot::YXZ, 0.6, 0.3, 0.9),
        Vec3::new(0.3, -0.2, 0.0),
    )
}

/// Where the pixel's ray meets the ellipsoid, and the normal there (None: it misses, or meets
/// it within a pixel or so of the rim, where the facets and the smooth shape part).
fn analytic_normal(camera: &Camera, x: u32, y: u32) -> Option<Vec3> {
    let (o, d) = camera.pixel_ray(x, y, SIZE, SIZE);
    let inv = transform().inverse();
    let (oo, dd) = (inv.transform_point3(o), inv.transform_vector3(d));
    // |oo + t·dd|² = 1
    let (a, b, c) = (dd.length_squared(), 2.0 * oo.dot(dd), oo.length_squared() - 1.0);
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return None;
    }
    let t = (-b - disc.sqrt()) / (2.0 * a);
    let n_object = oo + dd * t;
    let n = (Mat3::from_mat4(transform()).inverse().transpose() * n_object).normalize();
    // Not near the rim, where a pixel spans a wide range of normals.
    (n.dot(-d) > 0.3).then_some(n)
}

#[test]
fn a_turned_uneven_ellipsoid_has_the_analytic_normals() {
    let white = Material::named("white").unwrap();
    let object = Object {
        mesh: MeshKind::Sphere,
        transform: transform(),
        material: white,
        textures: Default::default(),
        extras: Default::default(),
    };
    let camera = Camera::looking_at(Vec3::new(0.0, 0.0, 6.0), Vec3::ZERO, 45.0, 0.1, 50.0);
    let light = PointLight { position_radius: [0.0, 3.0, 3.0, 20.0], color: [1.0, 1.0, 1.0, 0.0] };
    let scene = Scene::new(vec![object], vec![light], camera);
    let settings: Vec<RenderSettings> = [Technique::Forward, Technique::Deferred, Technique::DeferredCompute]
        .iter()
        .map(|&t| {
            let mut s = RenderSettings::new(t, SIZE, SIZE);
            s.debug_view = view("gbuffer-normal");
            s
        })
        .collect();
    for (out, s) in common::render_each(&scene, &settings).iter().zip(&settings) {
        let (mut checked, mut worst) = (0, 0.0f32);
        for y in 0..SIZE {
            for x in 0..SIZE {
                let Some(n) = analytic_normal(&camera, x, y) else { continue };
                let p = common::pixel(out, x, y);
                let shown = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32) / 255.0 * 2.0 - 1.0;
                worst = worst.max((shown - n).abs().max_element());
                checked += 1;
            }
        }
        println!("{}: {checked} pixels, worst normal component error {worst:.4}", s.technique.name());
        assert!(checked > 1000, "the ellipsoid should fill the view");
        // 8-bit display (±0.004) plus the facets: measured 0.0091.
        assert!(worst < 0.015, "{}: normals off by {worst}", s.technique.name());
    }
}
