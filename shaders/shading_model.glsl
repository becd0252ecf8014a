// Which shading model a pipeline is built for: a specialization constant (constant_id 10, set
// by raster.rs and deferred.rs from --shading), so each pipeline carries only its model's code.
// A uniform switch cost the seed model's fragment shaders 1.3–1.4× on the H100 (measured):
// the other model's code still took registers.

#ifndef MANYLIGHTS_SHADING_MODEL_GLSL
#define MANYLIGHTS_SHADING_MODEL_GLSL

layout(constant_id = 10) const bool MODEL_BLINN_PHONG = false;

#endif
