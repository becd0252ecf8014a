//! The renderer's GPU tests, one module per subject, in one test binary (one link, and the
//! test threads share every module's work instead of running file after file): image tests
//! against brute force and CPU references, golden images, layouts against SPIR-V reflection.
//! Run one subject with `cargo test -p ml-render --test gpu golden::`.

mod alpha_masks;
mod antialiasing;
mod cluster_slice;
mod common;
mod compute_raster;
mod culling;
mod debug_views;
mod deferred_pass;
mod environment;
mod exposure;
mod fitted_lights;
mod frames;
mod gltf_materials;
mod golden;
mod gpu_layout;
mod light_grid;
mod light_stats;
mod lobe_textures;
mod mask_shadows;
mod material_lobes;
mod omni_shadows;
mod reference;
mod renderer_changes;
mod scene_files;
mod shadow_atlas;
mod shadow_ray_traversal;
mod shadow_rays;
mod shadows;
mod spot_lights;
mod stage_probe;
mod techniques;
mod transforms;
mod transparency;
