//! Auto exposure's state from frame to frame: the EV the next frame is exposed with, the one
//! each frame slot's last frame used, and how a metered image moves it
//! (docs/DESIGN.md#exposure). The meter pass (`exposure_meter`) measures; this decides. The
//! renderer asks it whether a render's last image has settled (else that frame is rendered
//! again), and writes `multiplier` into the frame's uniforms.

use crate::exposure::{Exposure, MAX_EXPOSURE_EV};
use crate::frame_resources::FRAMES_IN_FLIGHT;

/// Auto exposure aims the log-average luminance at middle grey.
const KEY: f32 = 0.18;
/// A render's last frame is rendered again, at most this often, until the EV its own image
/// asks for is within SETTLED of the one it used (clipped pixels meter low, so the first
/// guess from a too-bright frame falls short).
pub const REPEATS: u32 = 4;
const SETTLED: f32 = 0.05;
/// In the viewer each frame moves the EV this share of the way to the metered one (about a
/// third of a second to settle at 60 frames a second).
pub const VIEWER_SMOOTHING: f32 = 0.1;

#[derive(Clone, Debug)]
pub struct AutoExposure {
    mode: Exposure,
    /// The EV the next frame is exposed with.
    ev: f32,
    /// Per frame slot: the EV its last frame used.
    slot_ev: [f32; FRAMES_IN_FLIGHT],
}

impl AutoExposure {
    pub fn new(mode: Exposure) -> AutoExposure {
        let mut e = AutoExposure { mode, ev: 0.0, slot_ev: [0.0; FRAMES_IN_FLIGHT] };
        e.set_mode(mode);
        e
    }

    /// Expose by `mode` from now on: a fixed EV is taken at once; auto goes on from the
    /// current EV.
    pub fn set_mode(&mut self, mode: Exposure) {
        self.mode = mode;
        if let Exposure::Ev(ev) = mode {
            self.ev = ev;
        }
    }

    /// Move the next frame's EV `share` of the way to the one that brings an image whose
    /// log2 log-average luminance is `log2_luminance` to the key (auto exposure, where the
    /// image was metered).
    pub fn adapt(&mut self, share: f32, log2_luminance: Option<f32>) {
        if let (Exposure::Auto, Some(log2_luminance)) = (self.mode, log2_luminance) {
            let wanted = (KEY.log2() - log2_luminance).clamp(-MAX_EXPOSURE_EV, MAX_EXPOSURE_EV);
            self.ev += (wanted - self.ev) * share;
        }
    }

    /// The next frame, in slot `slot`, is exposed now: the colour multiplier (2^EV).
    pub fn expose(&mut self, slot: usize) -> f32 {
        self.slot_ev[slot] = self.ev;
        self.ev.exp2()
    }

    /// Whether slot `slot`'s last frame used (within SETTLED) the EV it now asks for.
    pub fn settled(&self, slot: usize) -> bool {
        (self.ev - self.slot_ev[slot]).abs() <= SETTLED
    }

    /// The EV the next frame is exposed with.
    pub fn ev(&self) -> f32 {
        self.ev
    }

    /// The EV slot `slot`'s last frame used.
    pub fn slot_ev(&self, slot: usize) -> f32 {
        self.slot_ev[slot]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_fixed_ev_is_kept_and_auto_moves_toward_middle_grey() {
        let mut fixed = AutoExposure::new(Exposure::Ev(1.5));
        fixed.adapt(1.0, Some(-10.0));
        assert_eq!((fixed.ev(), fixed.expose(0)), (1.5, 1.5f32.exp2()));
        let mut auto = AutoExposure::new(Exposure::Auto);
        assert_eq!(auto.ev(), 0.0);
        // An image at middle grey asks for EV 0; one four times as bright for EV -2.
        auto.adapt(1.0, Some(KEY.log2() + 2.0));
        assert!((auto.ev() + 2.0).abs() < 1e-6);
        auto.adapt(0.5, Some(KEY.log2()));
        assert!((auto.ev() + 1.0).abs() < 1e-6, "half the way back");
        auto.adapt(1.0, None);
        assert!((auto.ev() + 1.0).abs() < 1e-6, "an image of nothing but background meters nothing");
        auto.adapt(1.0, Some(-1e9));
        assert_eq!(auto.ev(), MAX_EXPOSURE_EV, "clamped");
    }

    #[test]
    fn a_slot_has_settled_when_its_frame_used_the_ev_it_asks_for() {
        let mut e = AutoExposure::new(Exposure::Auto);
        e.expose(1);
        assert!(e.settled(1));
        e.adapt(1.0, Some(KEY.log2() - 1.0));
        assert!(!e.settled(1));
        e.expose(0);
        assert!(e.settled(0) && e.slot_ev(0) == 1.0);
    }
}
