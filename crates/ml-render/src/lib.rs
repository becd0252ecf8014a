//! manylights techniques and passes: what is drawn and how, on top of the Vulkan plumbing
//! (ml-vk) and the CPU scene (ml-cpu).

pub mod compute_pass;
pub mod depth_pass;
pub mod descriptors;
pub mod error;
pub mod frame;
pub mod frame_resources;
pub mod gpu_mesh;
pub mod mesh_raster;
pub mod meshlet_scene;
pub mod object_data;
pub mod object_textures;
pub mod omni_shadow;
pub mod pass;
pub mod passes;
pub mod render_pass;
pub mod renderer;
pub mod report;
pub mod scene_gpu;
pub mod scene_textures;
pub mod settings;
pub mod shadow_atlas;
pub mod shadow_raster;
pub mod stage_probe;
pub mod sun_shadow;
pub mod targets;

pub use error::RenderError;
pub use frame_resources::FRAMES_IN_FLIGHT;
pub use renderer::{FrameHook, FrameSink, RenderOutput, Renderer};
pub use settings::{
    DebugView, Exposure, Geometry, LargeTriangles, LightAssignment, LightingStage, OmniShadowMode, OmniShadowSettings, Raster,
    RenderSettings, Shading, ShadingModel, SunShadowMode, Technique, FRAME_SECONDS, TIMER_SPEED,
};
