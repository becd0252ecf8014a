//! How bright the image is: the exposure meter (auto exposure's log-average luminance) and
//! the tone map of the deferred subpass technique (docs/DESIGN.md#exposure).

pub mod auto_exposure;
pub mod exposure_meter;
pub mod tone_map;
