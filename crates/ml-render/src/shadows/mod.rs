//! Shadows: the stores (stores.rs, one interface over the point lights' cube array and
//! atlas, the sun's map and the shadow rays' hierarchy), their settings, the compute shadow
//! raster, and the passes that draw the shadowed lights' cubes (graphics or compute) or the
//! shadow atlas's faces each frame with their CPU step (placing the lights, planning the
//! atlas), and the debug view of the stores (docs/DESIGN.md#point-light-shadows).

pub mod omni_shadow;
pub mod omni_shadow_compute;
pub mod omni_shadow_pass;
pub mod ray_geometry;
pub mod shadow_atlas;
pub mod shadow_map_view;
pub mod shadow_raster;
pub mod shadow_settings;
pub mod stores;
pub mod sun_map;
pub mod sun_shadow;
