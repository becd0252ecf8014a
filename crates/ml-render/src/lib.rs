//! manylights techniques and passes: what is drawn and how, on top of the Vulkan plumbing
//! (ml-vk) and the CPU scene (ml-cpu).

pub mod assembly;
pub mod clusters;
pub mod compute_pass;
pub mod depth_pass;
pub mod descriptors;
pub mod error;
pub mod exposure;
pub mod frame;
pub mod frame_resources;
pub mod gpu_mesh;
pub mod pass;
pub mod plan;
pub mod render_pass;
pub mod renderer;
pub mod report;
pub mod scene;
pub mod settings;
pub mod shading;
pub mod shadows;
pub mod specialization;
pub mod stage_probe;
pub mod targets;
pub mod visibility;

pub use error::RenderError;
pub use frame_resources::FRAMES_IN_FLIGHT;
pub use renderer::{FrameHook, FrameSink, RenderOutput, Renderer};
pub use settings::{
    DebugView, Exposure, Geometry, LargeTriangles, LightAssignment, LightingStage, OmniShadowMode, OmniShadowSettings, Raster,
    RenderSettings, Shading, ShadingModel, SunShadowMode, Technique, FRAME_SECONDS, TIMER_SPEED,
};
