//! How bright the image is: the exposure meter (auto exposure's log-average luminance) and
//! the tone map of the deferred subpass technique (docs/DESIGN.md#exposure).

pub mod auto_exposure;
pub mod exposure_meter;
pub mod tone_map;

use crate::error::RenderError;

/// How bright the image is made (docs/DESIGN.md#exposure).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// Lit colour × 2^EV (0 changes nothing).
    Ev(f32),
    /// The EV that brings the image's log-average luminance to middle grey, metered on the
    /// GPU each frame (the exposure-meter pass) and applied to the next; a render's last frame
    /// is rendered again until the EV it used is the one its own image asks for.
    Auto,
}

/// The most |EV| `--exposure` takes (and auto exposure reaches): 2^±20 is a million times
/// brighter or darker, past any useful picture; beyond is a typo.
pub const MAX_EXPOSURE_EV: f32 = 20.0;

/// Parse `--exposure EV|auto`: auto, or a finite number of stops within ±MAX_EXPOSURE_EV.
pub fn parse_exposure(text: &str) -> Result<Exposure, RenderError> {
    if text.trim() == "auto" {
        return Ok(Exposure::Auto);
    }
    match text.trim().parse::<f32>() {
        Ok(ev) if ev.is_finite() && ev.abs() <= MAX_EXPOSURE_EV => Ok(Exposure::Ev(ev)),
        _ => Err(RenderError::Invalid(format!(
            "exposure '{text}' is neither auto nor a number of stops (EV) from -{MAX_EXPOSURE_EV} to {MAX_EXPOSURE_EV}"
        ))),
    }
}
