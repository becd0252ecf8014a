//! The renderer as a library: the bench scene with 4,096 lights, lit by the clustered
//! deferred technique, rendered headless and written to a PNG.
//! `cargo run --release -p ml-render --example headless [OUT.png]`

use ml_cpu::scene_request::{SceneRequest, SceneSource};
use ml_render::{Exposure, RenderSettings, Renderer, Technique};
use ml_vk::{Context, ContextDesc};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let out = std::env::args().nth(1).unwrap_or_else(|| "headless.png".into());
    // A scene: built in here; `SceneSource::File` loads a scene file or a glTF file.
    let mut request = SceneRequest::new(SceneSource::Bench { objects: ml_cpu::bench_scene::BENCH_OBJECTS });
    request.lights = Some(4096);
    let built = request.build()?;
    // A Vulkan device without a window (any Vulkan 1.2 device, lavapipe included).
    let ctx = Context::new(&ContextDesc { validation: false, device_index: None, window: None })?;
    // What to draw with: every setting has a default but the technique and the size; the
    // exposure is metered on the GPU.
    let settings =
        RenderSettings { shading: built.shading, exposure: Exposure::Auto, ..RenderSettings::new(Technique::DeferredClustered, 640, 360) };
    let output = Renderer::new(&ctx, built.scene, settings)?.render()?;
    // The image, replaced only once the PNG is complete.
    ml_cpu::files::write_png(std::path::Path::new(&out), &output.rgba, (output.width, output.height))?;
    // Each pass's GPU time (where the device has timestamps).
    let gpu_ms: f64 = output.stats.gpu_ms().unwrap_or_default().iter().map(|(_, ms)| ms).sum();
    println!("{out}: {}x{}, {gpu_ms:.3} GPU ms a frame", output.width, output.height);
    Ok(())
}
