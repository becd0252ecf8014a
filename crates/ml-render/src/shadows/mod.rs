//! Point-light shadows each frame: the passes that draw the shadowed lights' cubes (graphics
//! or compute) or the shadow atlas's faces, their CPU step (placing the lights, planning the
//! atlas), and the debug view of the shadow stores (docs/DESIGN.md#point-light-shadows). The
//! stores themselves — cube array, atlas, the sun's map — live with the scene (scene/).

pub mod omni_shadow_compute;
pub mod omni_shadow_pass;
pub mod shadow_map_view;
