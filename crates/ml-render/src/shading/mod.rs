//! The mesh techniques' raster passes: forward (brute force or clustered), the deferred
//! subpasses, the G-buffer and its compute lighting, and the render pass and mesh pipelines
//! they share.

pub mod compute_lighting;
pub mod deferred_subpass;
pub mod forward;
pub mod gbuffer;
pub mod mesh_raster;
