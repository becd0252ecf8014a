//! The visibility technique's GPU-driven geometry: the scene's meshlets, two-phase culling,
//! the visibility buffer drawn by the hardware or the compute raster, the depth pyramid, and
//! the lighting read from the visibility buffer (docs/DESIGN.md#visibility-buffer).

pub mod depth_pyramid;
pub mod meshlet_cull;
pub mod meshlet_scene;
pub mod triangle_raster_large;
pub mod visibility_gather;
pub mod visibility_lighting;
pub mod visibility_raster;
