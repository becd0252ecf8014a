//! manylights' renderer: a scene lit by many radius-limited point lights, drawn by one of
//! seven techniques (brute-force and clustered forward, deferred in subpasses or in compute,
//! a GPU-driven visibility buffer), with sun and point-light shadows, on top of the Vulkan
//! plumbing (ml-vk) and the CPU scene (ml-cpu).
//!
//! An embedder makes a [`Renderer`] for a [`ml_cpu::scene::Scene`] and [`RenderSettings`],
//! then renders headless ([`Renderer::render`]: the last frame read back, with its
//! [`report::FrameStats`]) or under a window ([`Renderer::draw`] with a [`FrameHook`] that
//! adds its commands and semaphores; the viewer crate is one). Settings are checked against
//! the device before anything is allocated; every error is a [`RenderError`] of one line.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use ml_render::{RenderSettings, Renderer, Technique};
//! let ctx = ml_vk::Context::new(&ml_vk::ContextDesc::default())?;
//! let scene = ml_cpu::scene::Scene::seed(
//!     ml_cpu::mesh::MeshKind::Teapot,
//!     ml_cpu::material::Material::named("gold").expect("a named material"),
//!     &ml_cpu::lights::LightParams::seed_default(),
//! )?;
//! let out = Renderer::new(&ctx, scene, RenderSettings::new(Technique::Visibility, 640, 360))?.render()?;
//! println!("{}x{} pixels, {:?} ms of GPU time", out.width, out.height, out.stats.gpu_ms());
//! # Ok(())
//! # }
//! ```
//!
//! Inside, a frame is a list of passes planned as data ([`plan::plan`]) and made by feature:
//! `shadows/`, `visibility/`, `clusters/`, `light_grid/`, `exposure/`, `shading/`, `transparency/`, `light_stats/`, over the scene's GPU
//! resources (`scene/`); docs/architecture.md maps every file.

pub mod error;
pub mod plan;
pub mod report;
pub mod settings;
pub mod stage_probe;

mod antialiasing;
mod assembly;
pub mod background;
mod clusters;
mod compute_pass;
mod debug_view;
mod depth_pass;
mod descriptors;
mod environment;
mod exposure;
mod feature;
mod frame;
mod frame_resources;
mod gpu_mesh;
mod light_grid;
mod light_stats;
mod pass;
mod read_back;
mod render_pass;
mod renderer;
mod scene;
mod scene_part;
mod shading;
mod shadows;
mod specialization;
mod sync;
mod targets;
mod technique;
mod transparency;
mod visibility;

pub use antialiasing::{auto_antialiasing, AntialiasingStats};
pub use background::Background;
pub use environment::EnvironmentView;
pub use error::RenderError;
pub use frame_resources::FRAMES_IN_FLIGHT;
pub use light_grid::LightGridStats;
pub use light_stats::LightStats;
pub use renderer::{FrameHook, FrameSink, RenderOutput, Renderer};
pub use settings::{
    layers_take, Antialiasing, DebugView, Exposure, Geometry, LargeTriangles, LightAssignment, LightGridMarks, LightingStage,
    OmniShadowMode, OmniShadowSettings, Raster, RenderSettings, Shading, ShadingModel, SunShadowMode, Technique, ViewNeed, FRAME_SECONDS,
    TIMER_SPEED,
};
pub use shadows::omni_shadow_compute::{AtlasStats, OmniRasterStats};
pub use shadows::ray_geometry::RayStats;
pub use shadows::stores::SHADOW_MAP_SIZE;
pub use targets::{gbuffer_bytes_per_pixel, gbuffer_images, GBufferImage, GBufferKind};
pub use transparency::{
    TransparencySettings, TransparencyStats, DEFAULT_BUDGET as DEFAULT_TRANSPARENCY_BUDGET, DEFAULT_CANDIDATE_LIST, LAYER_KEEP,
    MAX_BUDGET as MAX_TRANSPARENCY_BUDGET,
};
pub use visibility::meshlet_cull::CullStats;

/// What this crate's GPU tests inspect inside the renderer (render pass descriptions, set
/// layouts, push-constant layouts, target formats). Not part of the library's surface.
#[doc(hidden)]
pub mod internals {
    pub use crate::depth_pass::ShadowMaskPush;
    pub use crate::descriptors::{FrameSets, Resource};
    pub use crate::render_pass::{describe, RenderPassDesc};
    pub use crate::targets::{Output, HDR_FORMAT};
}
