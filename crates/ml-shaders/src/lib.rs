//! SPIR-V of the GLSL shaders under `shaders/`, compiled by this crate's build script.
//! Each `shaders/name.stage` becomes the constant `NAME_STAGE`; `ALL` lists them all.

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
