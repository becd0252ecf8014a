//! manylights techniques and passes: what is drawn and how, on top of the Vulkan plumbing
//! (ml-vk) and the CPU scene (ml-cpu).

pub mod cluster_build;
pub mod compute_pass;
pub mod deferred;
pub mod depth_pass;
pub mod error;
pub mod frame;
pub mod gpu_mesh;
pub mod headless;
pub mod object_textures;
pub mod omni_shadow;
pub mod raster;
pub mod render_pass;
pub mod report;
pub mod scene_textures;
pub mod settings;
pub mod stage_probe;
pub mod targets;
pub mod tonemap;

pub use error::RenderError;
pub use frame::FRAMES_IN_FLIGHT;
pub use headless::{FrameHook, HeadlessRenderer, RenderOutput};
pub use settings::{
    DebugView, OmniShadowMode, OmniShadowSettings, RenderSettings, Shading, ShadingModel, Technique, FRAME_SECONDS, TIMER_SPEED,
};
