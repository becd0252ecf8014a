//! GPU vs CPU reference: one sphere and a few lights at 256×256. For every pixel whose ray
//! hits the analytic unit sphere (ray-cast here on the CPU), the GPU pixel must match the
//! CPU reference shading of that exact point and normal.
//!
//! Tolerance: the GPU shades the tessellated sphere (64×128 facets, within 3e-4 of the true
//! surface) with interpolated positions and normals; the CPU shades the exact surface. The
//! two normals differ by up to about 1e-3 rad. For a rough surface that moves no pixel by
//! more than an 8-bit step, but the seed's roughness 0.1 makes highlights 0.01 rad wide, where
//! 1e-3 rad is ~10/255. So each pixel must lie within 2/255 of the range the CPU reference
//! takes when its normal is tilted by up to NORMAL_TOLERANCE (2e-3 rad, twice the facet
//! error) — on flat regions that range is one value, so the check is as strict as 2/255.
//! Pixels where the view grazes the sphere (N·V < 0.2) are skipped: there a pixel centre can
//! miss the tessellated mesh altogether. The mean absolute difference must also stay small.

use crate::common;

use glam::Vec3;
use ml_cpu::camera::Camera;
use ml_cpu::gpu_types::PointLight;
use ml_cpu::lights::animate_into;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::{DirectionalLight, Object, Scene};
use ml_cpu::shading::{encode_gamma_unorm8, shade_seed};

const SIZE: u32 = 256;
/// Allowed difference beyond the reference's range, in 8-bit steps (float32 vs float32
/// with different operation order, and UNORM rounding).
const MAX_DIFF: u8 = 2;
const NORMAL_TOLERANCE: f32 = 2e-3;
const MAX_MEAN_DIFF: f64 = 0.05;

fn light(p: [f32; 3], radius: f32, color: [f32; 3]) -> PointLight {
    PointLight { position_radius: [p[0], p[1], p[2], radius], color: [color[0], color[1], color[2], 0.0] }
}

fn sphere_scene(material: Material) -> Scene {
    let lights = vec![
        light([2.0, 2.0, 2.0], 6.0, [1.0, 0.2, 0.1]),
        light([-2.5, 0.5, 1.5], 4.0, [0.1, 1.0, 0.3]),
        light([0.0, -2.0, 2.5], 4.5, [0.2, 0.3, 1.0]),
        // Its sphere of influence ends inside the object: a hard cut-off across the surface.
        light([0.5, 2.2, 0.5], 1.8, [1.0, 1.0, 0.0]),
    ];
    let camera = Camera::looking_at(Vec3::new(0.3, 0.6, 3.2), Vec3::ZERO, 45.0, 0.1, 100.0);
    Scene::new(vec![Object::placed(MeshKind::Sphere, Vec3::ZERO, 1.0, material)], lights, camera)
}

fn compare(material: Material, directional: &[DirectionalLight], orthographic: Option<f32>) {
    let mut scene = sphere_scene(material);
    scene.directional = directional.to_vec();
    scene.camera.orthographic = orthographic;
    let out = common::render(scene.clone(), common::settings(SIZE, SIZE));
    let cam = &scene.camera;
    // The renderer animates lights (time 0 moves them by (0, 0, 0.1)); shade what it drew.
    let mut lights = scene.lights.clone();
    animate_into(&scene.lights, 0.0, &mut lights);
    let r = common::compare_sphere(&out, cam, false, (NORMAL_TOLERANCE, MAX_DIFF), |p, dir| {
        // A directional light is the seed's point light with no falloff, from one direction:
        // on the CPU, exactly that (a light 10⁴ m back along it whose radius never ends).
        let mut all = lights.clone();
        all.extend(directional.iter().map(|d| PointLight {
            position_radius: (p - d.direction * 1e4).extend(1e30).to_array(),
            color: d.color.extend(0.0).to_array(),
        }));
        // An orthographic camera looks along its axis at every point: an eye far back on the ray.
        let eye = if orthographic.is_some() { p - dir * 1e5 } else { cam.position };
        let ambient = scene.ambient;
        move |n: Vec3| encode_gamma_unorm8(shade_seed(p, n, eye, &material, &all, ambient))
    });
    let (compared, outside) = (r.compared, r.outside);
    let mean = r.sum as f64 / (compared as f64 * 3.0);
    assert!(compared > 20_000, "the sphere should cover much of the image, got {compared} pixels");
    assert_eq!(outside, 0, "channels outside the reference range ± {MAX_DIFF}/255");
    assert!(mean < MAX_MEAN_DIFF, "mean difference {mean}/255");
}

#[test]
fn gpu_matches_cpu_reference_on_a_seed_material() {
    compare(Material::named("gold").unwrap(), &[], None);
}

#[test]
fn an_orthographic_camera_matches_the_cpu_reference() {
    compare(Material::named("gold").unwrap(), &[], Some(1.3));
}

#[test]
fn gpu_matches_cpu_reference_on_a_rough_dielectric() {
    compare(Material { albedo: Vec3::new(0.8, 0.3, 0.2), roughness: 0.6, metallic: 0.0 }, &[], None);
}

#[test]
fn directional_lights_match_the_cpu_reference() {
    let sun = DirectionalLight { direction: Vec3::new(0.5, -1.0, -0.3).normalize(), color: Vec3::new(0.6, 0.6, 0.5) };
    let fill = DirectionalLight { direction: Vec3::new(-0.8, 0.4, -0.6).normalize(), color: Vec3::new(0.1, 0.2, 0.4) };
    // Six: any number (the frame's uniforms once held four).
    let dim = |x: f32, y: f32, z: f32, c: [f32; 3]| DirectionalLight { direction: Vec3::new(x, y, z).normalize(), color: Vec3::from(c) };
    let more = [
        dim(0.2, -0.3, -1.0, [0.15, 0.05, 0.0]),
        dim(-0.5, -0.5, -0.7, [0.0, 0.12, 0.05]),
        dim(0.9, 0.1, -0.4, [0.05, 0.0, 0.15]),
        dim(0.0, 1.0, -0.2, [0.1, 0.1, 0.1]),
    ];
    let six: Vec<DirectionalLight> = [sun, fill].into_iter().chain(more).collect();
    compare(Material { albedo: Vec3::new(0.8, 0.3, 0.2), roughness: 0.6, metallic: 0.0 }, &six, None);
    compare(Material::named("gold").unwrap(), &[sun], None);
}
