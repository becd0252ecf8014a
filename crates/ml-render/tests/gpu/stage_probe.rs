//! The compute-vs-fragment probe measures what it says: both halves compute the same image —
//! the CPU reference of the seed BRDF summed over every light — over the same pixels, with
//! validation (and synchronization validation) silent, and `--technique auto`'s quick probe
//! returns a measured ratio.

use glam::Vec3;
use ml_cpu::material::Material;
use ml_cpu::shading::seed_point_light;
use ml_render::settings::missing_meshlet_feature;
use ml_render::stage_probe::{pick_lighting_path, probe_lights, quick_probe, StageProbe};
use ml_render::Technique;
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;

fn validated() -> Context {
    Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("a Vulkan device with the validation layer")
}

/// stage_probe.glsl's pixel on the CPU: the floor point, the eye, gold at roughness 0.3.
/// `lights`: the first lights of the probe's buffer, the ones its loop sums.
fn reference(x: u32, y: u32, (w, h): (u32, u32), lights: &[ml_cpu::gpu_types::PointLight]) -> [u8; 3] {
    let uv = (Vec3::new(x as f32, y as f32, 0.0) + 0.5) / Vec3::new(w as f32, h as f32, 1.0);
    let world = Vec3::new(uv.x * 40.0 - 20.0, 0.0, uv.y * 40.0 - 20.0);
    let v = (Vec3::new(0.0, 15.0, 25.0) - world).normalize();
    let gold = Material { albedo: Vec3::new(1.0, 0.765557, 0.336057), roughness: 0.3, metallic: 1.0 };
    let sum: Vec3 = lights.iter().map(|l| seed_point_light(l, world, Vec3::Y, v, &gold)).sum();
    let c = sum / (Vec3::ONE + sum);
    [c.x, c.y, c.z].map(|v| (v.clamp(0.0, 1.0) * 255.0).round() as u8)
}

#[test]
fn both_halves_shade_the_reference_image() {
    let ctx = validated();
    let messages = ctx.validation_counter();
    let size = (48, 32);
    let mut probe = StageProbe::new(&ctx, size.0, size.1, 64).expect("probe");
    let mut images = Vec::new();
    let buffer = probe_lights(64);
    for lights in [64, 5] {
        let t = probe.measure(&ctx, lights, 1, 2).expect("measure");
        assert_eq!((t.lights, t.pixels), (lights, 48 * 32));
        for s in [t.fragment, t.compute] {
            assert!(s.median > 0.0 && s.median.is_finite() && s.median <= s.p95, "{s:?}");
        }
        assert!(t.ratio().is_finite() && t.ratio() > 0.0);
        let (fragment, compute) = probe.read_images(&ctx).expect("read back");
        let mut worst = 0;
        for (i, (f, c)) in fragment.chunks_exact(4).zip(compute.chunks_exact(4)).enumerate() {
            let (x, y) = (i as u32 % size.0, i as u32 / size.0);
            let r = reference(x, y, size, &buffer[..lights as usize]);
            for k in 0..3 {
                worst = worst.max(f[k].abs_diff(r[k])).max(c[k].abs_diff(r[k]));
            }
            assert_eq!((f[3], c[3]), (255, 255));
        }
        assert!(worst <= 1, "{lights} lights: a half differs from the CPU reference by {worst}/255");
        images.push(fragment);
    }
    // The loop length is honoured: 5 lights make another image than 64.
    assert_ne!(images[0], images[1]);
    probe.destroy(&ctx);
    drop(ctx);
    assert_eq!(messages.load(Ordering::SeqCst), 0, "validation messages (printed above)");
}

#[test]
fn the_quick_probe_measures_a_ratio_and_picks_a_path() {
    let ctx = validated();
    let messages = ctx.validation_counter();
    let t = quick_probe(&ctx).expect("quick probe");
    assert!(t.lights >= 16 && t.lights <= 4096 && t.pixels == 512 * 512);
    assert!(t.ratio().is_finite() && t.ratio() > 0.0, "{t:?}");
    let meshlets = missing_meshlet_feature(&ctx.info.features).is_none();
    let (technique, why) = pick_lighting_path(&t, meshlets);
    assert!(technique.lights_in_compute() || technique.lights_in_subpass(), "{}", technique.name());
    // Only a device that runs the meshlet passes is sent to the visibility buffer.
    assert!(meshlets || technique != Technique::Visibility, "{}", technique.name());
    assert!(why.contains(&format!("{} lights", t.lights)), "{why}");
    drop(ctx);
    assert_eq!(messages.load(Ordering::SeqCst), 0, "validation messages (printed above)");
}
