//! Shared harness for image tests: a validated context, render → read back, compare.
//! Validation (with synchronization validation) is always on; any message fails the test,
//! including those the layer reports while the device and instance are destroyed.

#![allow(dead_code)]

use ml_cpu::scene::Scene;
use ml_render::{HeadlessRenderer, RenderOutput, RenderSettings, Technique};
use ml_vk::{Context, ContextDesc};
use std::sync::atomic::Ordering;

pub fn settings(width: u32, height: u32) -> RenderSettings {
    RenderSettings { technique: Technique::Forward, width, height, frames: 1, time: Some(0.0) }
}

/// Render on a fresh validated context and check the layer said nothing.
pub fn render(scene: Scene, settings: RenderSettings) -> RenderOutput {
    let ctx = Context::new(&ContextDesc { validation: true, device_index: None })
        .expect("a Vulkan device with the validation layer (CI installs lavapipe and vulkan-validationlayers)");
    let counter = ctx.validation_counter();
    let output = {
        let mut renderer = HeadlessRenderer::new(&ctx, scene, settings).expect("renderer");
        renderer.render().expect("render")
    };
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages (printed above)");
    output
}

pub fn pixel(out: &RenderOutput, x: u32, y: u32) -> [u8; 3] {
    let i = ((y * out.width + x) * 4) as usize;
    [out.rgba[i], out.rgba[i + 1], out.rgba[i + 2]]
}
