//! Shared harness for image tests: a validated context, render → read back, compare.
//! Validation (with synchronization validation) is always on; any message fails the test.
//!
//! The renders of `render` and `render_each` share validated contexts (`pooled_context`):
//! on lavapipe making a context, and every pipeline a renderer makes on it, costs time that
//! a context kept between tests saves (its pipeline cache serves the next test). After each
//! use the context must hold no pipeline and no memory (what a renderer leaked there fails
//! that test); what else it may leak the layer reports when the pooled contexts are destroyed
//! as the test binary exits, which then exits with an error. Tests that need a context of
//! their own (a device's destruction, counts of pipelines made) make one.

#![allow(dead_code)] // each test binary uses part of the harness

pub mod shadow_rays;

use ml_cpu::scene::Scene;
use ml_render::{FrameSink, RenderError, RenderOutput, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;
use std::sync::{Mutex, Once};

pub fn settings(width: u32, height: u32) -> RenderSettings {
    RenderSettings::new(Technique::Forward, width, height)
}

/// Render on a fresh validated context and check the layer said nothing.
pub fn render(scene: Scene, settings: RenderSettings) -> RenderOutput {
    render_each(&scene, &[settings]).pop().expect("one output")
}

/// Render the scene once per settings on one validated context; no validation message allowed.
pub fn render_each(scene: &Scene, settings: &[RenderSettings]) -> Vec<RenderOutput> {
    render_each_on_driver(scene, settings).0
}

/// `render_each`, and the name of the driver that rendered (Vulkan's `driverName`).
pub fn render_each_on_driver(scene: &Scene, settings: &[RenderSettings]) -> (Vec<RenderOutput>, String) {
    let ctx = pooled_context();
    let outputs = settings
        .iter()
        .map(|s| {
            let mut renderer = Renderer::new(&ctx, scene.clone(), *s).expect("renderer");
            renderer.render().expect("render")
        })
        .collect();
    let driver = ctx.info.driver_name.clone();
    (outputs, driver)
}

/// Validated contexts between uses.
static POOL: Mutex<Vec<Context>> = Mutex::new(Vec::new());

/// A validated context of the pool's (made where none is free), given back when dropped after
/// the checks above: no validation message while it was used, no pipeline held and no memory
/// allocated any more. A test that panics drops its context instead.
pub struct PooledContext {
    ctx: Option<Context>,
    messages: u32,
}

pub fn pooled_context() -> PooledContext {
    let ctx = POOL.lock().unwrap_or_else(|e| e.into_inner()).pop().unwrap_or_else(|| {
        Context::new(&ContextDesc { validation: true, ..Default::default() })
            .expect("a Vulkan device with the validation layer (CI installs lavapipe and vulkan-validationlayers)")
    });
    // Registered once a context exists: handlers run in the reverse of their registration,
    // so this one runs before the static destructors of the layer and driver loaded for it.
    static EXIT_CHECK: Once = Once::new();
    EXIT_CHECK.call_once(|| {
        // SAFETY: registers a plain function to run at exit.
        unsafe { libc::atexit(destroy_pool) };
    });
    let messages = ctx.validation_counter().load(Ordering::SeqCst);
    PooledContext { ctx: Some(ctx), messages }
}

impl std::ops::Deref for PooledContext {
    type Target = Context;
    fn deref(&self) -> &Context {
        self.ctx.as_ref().expect("held until dropped")
    }
}

impl Drop for PooledContext {
    fn drop(&mut self) {
        let ctx = self.ctx.take().expect("held until dropped");
        if std::thread::panicking() {
            return;
        }
        let messages = ctx.validation_counter().load(Ordering::SeqCst) - self.messages;
        let (_, held) = ctx.pipeline_counts();
        let allocations = ctx.memory_use().allocations;
        if messages > 0 || held > 0 || allocations > 0 {
            drop(ctx);
            panic!("{messages} validation messages (printed above); {held} pipelines still held; {allocations} allocations left");
        }
        POOL.lock().unwrap_or_else(|e| e.into_inner()).push(ctx);
    }
}

/// At exit: destroy the pooled contexts, and exit with an error where the layer reported
/// anything as they went (objects left alive on a device are reported at its destruction).
extern "C" fn destroy_pool() {
    let contexts = std::mem::take(&mut *POOL.lock().unwrap_or_else(|e| e.into_inner()));
    for ctx in contexts {
        let counter = ctx.validation_counter();
        let before = counter.load(Ordering::SeqCst);
        drop(ctx);
        let reported = counter.load(Ordering::SeqCst) - before;
        if reported > 0 {
            eprintln!("error: the validation layer reported {reported} messages (above) as a pooled test context was destroyed");
            // SAFETY: ends the process at once (exit's handlers are running).
            unsafe { libc::_exit(1) };
        }
    }
}

/// Largest per-channel difference between two images of the same size, and how many
/// pixels differ at all.
pub fn max_difference(a: &RenderOutput, b: &RenderOutput) -> (u8, usize) {
    assert_eq!((a.width, a.height), (b.width, b.height));
    rgba_difference(&a.rgba, &b.rgba)
}

/// Collects every frame's image (an image sequence), in the order handed over.
#[derive(Default)]
pub struct Frames(pub Vec<Vec<u8>>);

impl FrameSink for Frames {
    fn wants_images(&self) -> bool {
        true
    }
    fn image(&mut self, _i: u32, rgba: Vec<u8>) -> Result<(), RenderError> {
        self.0.push(rgba);
        Ok(())
    }
}

/// `max_difference` of two RGBA byte arrays of one size.
pub fn rgba_difference(a: &[u8], b: &[u8]) -> (u8, usize) {
    assert_eq!(a.len(), b.len(), "images of one size");
    let mut worst = 0;
    let mut pixels = 0;
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let d = pa.iter().zip(pb).map(|(x, y)| x.abs_diff(*y)).max().unwrap();
        worst = worst.max(d);
        pixels += (d > 0) as usize;
    }
    (worst, pixels)
}

/// Pixels whose largest channel difference exceeds `limit`.
pub fn pixels_beyond(a: &RenderOutput, b: &RenderOutput, limit: u8) -> usize {
    a.rgba.chunks_exact(4).zip(b.rgba.chunks_exact(4)).filter(|(pa, pb)| pa.iter().zip(*pb).any(|(x, y)| x.abs_diff(*y) > limit)).count()
}

/// First intersection of a ray with the unit sphere at the origin (the reference tests' sphere).
pub fn hit_unit_sphere(origin: glam::Vec3, dir: glam::Vec3) -> Option<glam::Vec3> {
    let b = origin.dot(dir);
    let c = origin.length_squared() - 1.0;
    let disc = b * b - c;
    (disc >= 0.0).then(|| origin + dir * (-b - disc.sqrt()))
}

/// Where a pixel `got` of a tessellated surface leaves its CPU reference: `shade` (the
/// reference's 8-bit colour for a normal) at the exact normal `n` is `expected`; each channel
/// may take any value the reference takes with `n` tilted by `tilt` rad (the facets' error),
/// widened by `margin` steps. Returns `expected` and the channels outside, with their range.
pub fn outside_reference(
    shade: impl Fn(glam::Vec3) -> [u8; 3],
    n: glam::Vec3,
    tilt: f32,
    (got, margin): ([u8; 3], u8),
) -> ([u8; 3], Vec<(usize, std::ops::RangeInclusive<u8>)>) {
    let expected = shade(n);
    let (t1, t2) = n.any_orthonormal_pair();
    let tilted = [t1, -t1, t2, -t2].map(|t| shade((n + t * tilt).normalize()));
    let outside = (0..3)
        .filter_map(|c| {
            let lo = tilted.iter().map(|s| s[c]).fold(expected[c], u8::min).saturating_sub(margin);
            let hi = tilted.iter().map(|s| s[c]).fold(expected[c], u8::max).saturating_add(margin);
            (!(lo..=hi).contains(&got[c])).then_some((c, lo..=hi))
        })
        .collect();
    (expected, outside)
}

/// How a rendered unit sphere compares with its CPU reference (`compare_sphere`): pixels
/// compared, channels outside the reference's range, the largest and the summed difference
/// from the reference at the exact normal.
pub struct SphereComparison {
    pub compared: u32,
    pub outside: u32,
    pub worst: u8,
    pub sum: u64,
}

/// Compare each pixel of `out` whose camera ray hits the unit sphere at the origin with its CPU
/// reference: every pixel, or every other one (a checkerboard) with `checker`, skipping those
/// where the view grazes the sphere (N·V < 0.2: a pixel centre may miss the facets there).
/// `shade(point, ray direction)` gives the reference's 8-bit colour for a normal at that point,
/// compared by `outside_reference` with `tilt` and `margin`; the first channels outside are
/// printed, and the summary.
pub fn compare_sphere<F: Fn(glam::Vec3) -> [u8; 3]>(
    out: &RenderOutput,
    cam: &ml_cpu::camera::Camera,
    checker: bool,
    (tilt, margin): (f32, u8),
    shade: impl Fn(glam::Vec3, glam::Vec3) -> F,
) -> SphereComparison {
    let (w, h) = (out.width, out.height);
    let mut r = SphereComparison { compared: 0, outside: 0, worst: 0, sum: 0 };
    for y in 0..h {
        let step = if checker { 2 } else { 1 };
        for x in ((if checker { y % 2 } else { 0 })..w).step_by(step) {
            let (origin, dir) = cam.pixel_ray(x, y, w, h);
            let Some(p) = hit_unit_sphere(origin, dir) else { continue };
            let n = p.normalize();
            if n.dot(-dir) < 0.2 {
                continue;
            }
            let got = pixel(out, x, y);
            let (expected, off) = outside_reference(shade(p, dir), n, tilt, (got, margin));
            for c in 0..3 {
                let d = got[c].abs_diff(expected[c]);
                r.worst = r.worst.max(d);
                r.sum += u64::from(d);
            }
            for (c, range) in off {
                r.outside += 1;
                if r.outside <= 20 {
                    println!("pixel ({x}, {y}) channel {c}: gpu {} outside the reference range {range:?}", got[c]);
                }
            }
            r.compared += 1;
        }
    }
    let mean = r.sum as f64 / (f64::from(r.compared.max(1)) * 3.0);
    println!(
        "{} pixels compared: max |gpu − cpu| {}/255, mean {mean:.4}/255, {} channels outside the tolerance",
        r.compared, r.worst, r.outside
    );
    r
}

pub fn pixel(out: &RenderOutput, x: u32, y: u32) -> [u8; 3] {
    let i = ((y * out.width + x) * 4) as usize;
    [out.rgba[i], out.rgba[i + 1], out.rgba[i + 2]]
}

/// `pixel` at (x, y), None outside the image (for looking at a pixel's neighbours).
pub fn pixel_at(out: &RenderOutput, x: i64, y: i64) -> Option<[u8; 3]> {
    let inside = x >= 0 && y >= 0 && x < out.width as i64 && y < out.height as i64;
    inside.then(|| pixel(out, x as u32, y as u32))
}

/// Whether a depth-map texel holds a surface (1.0: cleared, nothing in reach).
pub fn reached(depth: f32) -> bool {
    depth < 1.0
}

/// The texels (index, a's depth, b's depth) that one of two depth maps covers and the other
/// does not, with how many texels differ at all.
pub fn coverage_difference(a: &[f32], b: &[f32]) -> (Vec<(usize, f32, f32)>, usize) {
    assert_eq!(a.len(), b.len());
    let one_only = a.iter().zip(b).enumerate().filter(|(_, (x, y))| reached(**x) != reached(**y)).map(|(i, (&x, &y))| (i, x, y)).collect();
    (one_only, a.iter().zip(b).filter(|(x, y)| x != y).count())
}

/// Run a probe compute shader once over `invocations` threads with its set 0 bound by block
/// name from `buffers`, and wait for it (its host-visible outputs are then readable).
pub fn dispatch_probe(ctx: &Context, probe: &ml_shaders::Shader, buffers: &[(&str, ash::vk::Buffer)], invocations: u32) {
    use ash::vk;
    use ml_render::internals::{FrameSets, Resource};
    let mut sets = FrameSets::new(ctx, &[(probe, vk::ShaderStageFlags::COMPUTE)], 0, 1).unwrap();
    let pipeline_layout = ml_vk::shader::pipeline_layout(ctx, &[sets.layout.raw], &[]).unwrap();
    let pipeline = ml_vk::shader::compute_pipeline(ctx, probe.file, probe.spirv, pipeline_layout, &[]).unwrap();
    sets.write(ctx, 0, &|name| buffers.iter().find(|(n, _)| *n == name).map(|(_, b)| Resource::Buffer(*b))).unwrap();
    ml_vk::commands::one_shot(ctx, |cmd| {
        // SAFETY: recording state; all bound objects are alive.
        unsafe {
            ctx.device.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, pipeline);
            ctx.device.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, pipeline_layout, 0, &[sets.sets[0]], &[]);
            let [groups, ..] = probe.groups([invocations, 1, 1]);
            ctx.device.cmd_dispatch(cmd, groups, 1, 1);
        }
        ml_vk::commands::memory_barrier(
            ctx,
            cmd,
            (vk::PipelineStageFlags::COMPUTE_SHADER, vk::AccessFlags::SHADER_WRITE),
            (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
        );
    })
    .expect("probe dispatch");
    ml_vk::shader::release_pipeline(ctx, pipeline);
    sets.destroy(ctx);
}

/// The debug view of that name.
pub fn view(name: &str) -> ml_render::DebugView {
    ml_render::DebugView::from_name(name).expect("a debug view")
}
