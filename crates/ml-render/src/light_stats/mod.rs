//! Light statistics (`render --light-stats`): per pixel with a surface, the lights the light
//! loop tests there against the lights that reach the point, summed over the frame
//! (`light_count`). Their ratio is the work light culling leaves that lights nothing: exact
//! culling keeps every image the same, so this is the figure a better light structure moves.

pub mod light_count;

use crate::report::FeatureStats;

/// The light counts of the last frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LightStats {
    /// Pixels with a surface.
    pub pixels: u64,
    /// Lights tested, summed over those pixels.
    pub tested: u64,
    /// Lights whose sphere holds the pixel's surface point, summed over those pixels.
    pub reached: u64,
}

impl LightStats {
    /// Lights tested per pixel with a surface.
    pub fn tested_per_pixel(&self) -> f64 {
        self.tested as f64 / self.pixels.max(1) as f64
    }

    /// Lights reaching per pixel with a surface.
    pub fn reached_per_pixel(&self) -> f64 {
        self.reached as f64 / self.pixels.max(1) as f64
    }

    /// Lights tested per light reaching (1: nothing wasted; None where none reaches).
    pub fn tested_per_reached(&self) -> Option<f64> {
        (self.reached > 0).then(|| self.tested as f64 / self.reached as f64)
    }
}

impl FeatureStats for LightStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let ratio = self.tested_per_reached().map_or_else(|| "no light reaches".to_owned(), |r| format!("{r:.2} tested per reaching"));
        vec![(
            "lights per pixel",
            format!(
                "{:.2} tested, {:.2} reaching ({ratio}; {} pixels with a surface)",
                self.tested_per_pixel(),
                self.reached_per_pixel(),
                self.pixels
            ),
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_row_gives_both_counts_per_pixel_and_their_ratio() {
        let s = LightStats { pixels: 4, tested: 40, reached: 8 };
        assert_eq!((s.tested_per_pixel(), s.reached_per_pixel(), s.tested_per_reached()), (10.0, 2.0, Some(5.0)));
        let row = &s.rows()[0];
        assert_eq!(row.0, "lights per pixel");
        assert_eq!(row.1, "10.00 tested, 2.00 reaching (5.00 tested per reaching; 4 pixels with a surface)");
        assert_eq!(LightStats::default().tested_per_reached(), None);
    }
}
