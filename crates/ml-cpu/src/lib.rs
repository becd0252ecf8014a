//! The CPU half of manylights: everything that needs no GPU. Scene data (meshes, materials,
//! lights, camera), the structs shared with the shaders, and the CPU reference of each
//! shading model that the image tests compare the GPU against.

pub mod alpha_mask;
pub mod bench_scene;
pub mod blinn_phong;
pub mod camera;
pub mod cluster;
pub mod environment;
pub mod error;
pub mod file_fields;
pub mod files;
pub mod forest;
pub mod framing;
mod geometry;
pub mod gltf_scene;
pub mod gltf_writer;
pub mod gpu_types;
pub mod image_decode;
pub mod light_grid;
pub mod lights;
pub mod limits;
pub mod material;
pub mod material_lobes;
pub mod mesh;
pub mod meshlets;
pub mod omni_shadow;
pub mod random_scene;
pub mod ray_bvh;
pub mod scene;
pub mod scene_file;
pub mod scene_load;
pub mod scene_request;
pub mod scene_section;
pub mod section_kind;
pub mod sections;
pub mod shading;
pub mod shading_model;
pub mod shadow_atlas;
pub mod supersample;
pub mod surface_sampler;
mod teapot;
pub mod textures;
pub mod transparency;
pub mod twin_faces;

pub use error::SceneError;
