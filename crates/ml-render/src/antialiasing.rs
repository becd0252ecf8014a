//! Anti-aliasing (docs/DESIGN.md#anti-aliasing): coverage samples per pixel — in the compute
//! and hybrid rasters' 64-bit buffer (`VISIBILITY_SAMPLES` in visibility/visibility_samples.glsl),
//! or in the mesh techniques' multisampled attachments — each distinct surface of a pixel
//! shaded once, the pixel the mean of its samples in the display's linear light.

use crate::error::{by_name, Named, RenderError};
use crate::report::FeatureStats;
use ml_vk::vk;

/// Coverage samples per pixel (`--aa`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Antialiasing {
    /// One sample, at the pixel centre.
    Off,
    X4,
    X8,
    X16,
}

impl Antialiasing {
    pub const ALL: [Antialiasing; 4] = [Antialiasing::Off, Antialiasing::X4, Antialiasing::X8, Antialiasing::X16];

    pub fn name(self) -> &'static str {
        match self {
            Antialiasing::Off => "off",
            Antialiasing::X4 => "4",
            Antialiasing::X8 => "8",
            Antialiasing::X16 => "16",
        }
    }

    pub fn from_name(name: &str) -> Result<Antialiasing, RenderError> {
        by_name(&Antialiasing::ALL, Antialiasing::name, Named::Antialiasing, name)
    }

    /// Samples per pixel (1 when off).
    pub fn samples(self) -> u32 {
        match self {
            Antialiasing::Off => 1,
            Antialiasing::X4 => 4,
            Antialiasing::X8 => 8,
            Antialiasing::X16 => 16,
        }
    }

    /// Samples per pixel as Vulkan counts them (the mesh techniques' multisampled attachments).
    pub fn sample_count(self) -> vk::SampleCountFlags {
        vk::SampleCountFlags::from_raw(self.samples())
    }

    /// The specialization constant of the shaders that read or write the samples.
    pub fn constant(self) -> (&'static str, u32) {
        ("VISIBILITY_SAMPLES", self.samples())
    }

    /// Bytes the compute raster's buffer takes at `width`×`height`: depth and id, 8 bytes a
    /// sample.
    pub fn buffer_bytes(self, width: u32, height: u32) -> u64 {
        u64::from(width) * u64::from(height) * 8 * u64::from(self.samples())
    }
}

/// What `--aa auto` (the default) takes on a device (docs/DESIGN.md#anti-aliasing), and why:
/// - a CPU driver: none — every sample costs its share of the frame on the same cores
///   (lavapipe, the seed scene at 1280×720: 161 ms a frame without, 560 ms at 4 samples);
/// - a GPU: 8 samples (the H200, the bench scene at 1080p with 1M lights: 0.42 ms a frame
///   without, 1.22 ms at 8 — the image against a supersampled reference: 0.30 of the error
///   without, 0.40 at 4), or 4 where the settings take no 8 (`takes`: the technique's
///   attachments, transparent layers), else none, saying why.
pub fn auto_antialiasing(cpu_driver: bool, takes: impl Fn(Antialiasing) -> Result<(), RenderError>) -> (Antialiasing, String) {
    if cpu_driver {
        return (Antialiasing::Off, "a CPU driver: each sample costs the frame its share (--aa 4 or 8 for stills)".to_owned());
    }
    let mut refused = None;
    for aa in [Antialiasing::X8, Antialiasing::X4] {
        match takes(aa) {
            Ok(()) if refused.is_none() => return (aa, "a GPU: 8 samples a pixel".to_owned()),
            Ok(()) => return (aa, format!("a GPU: 8 samples a pixel where they are taken, not here ({})", refused.unwrap_or_default())),
            Err(e) => refused = refused.or(Some(e.to_string())),
        }
    }
    (Antialiasing::Off, format!("a GPU, but these settings take no samples: {}", refused.unwrap_or_default()))
}

/// What anti-aliasing took in the last frame: its samples' memory, and the surfaces the
/// lighting shaded (a pixel shades each surface its samples hold).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AntialiasingStats {
    pub antialiasing: Antialiasing,
    pub width: u32,
    pub height: u32,
    /// Bytes its samples take: the compute raster's buffer, or the mesh techniques'
    /// multisampled attachments.
    pub sample_bytes: u64,
    /// Surfaces shaded in the last frame, summed over the pixels, where the lighting counts
    /// them (the visibility technique; the mesh techniques shade each surface a pixel's
    /// samples hold once too, uncounted).
    pub surfaces: Option<u64>,
}

impl AntialiasingStats {
    /// Surfaces shaded per pixel (the background counts none), where counted.
    pub fn surfaces_per_pixel(&self) -> Option<f64> {
        Some(self.surfaces? as f64 / (f64::from(self.width) * f64::from(self.height)).max(1.0))
    }
}

impl FeatureStats for AntialiasingStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let mib = self.sample_bytes as f64 / f64::from(1 << 20);
        let shaded = match self.surfaces_per_pixel() {
            Some(s) => format!("{s:.3} surfaces shaded a pixel in the last frame"),
            None => "each surface a pixel's samples hold shaded once (not counted)".to_owned(),
        };
        vec![("anti-aliasing", format!("{} samples a pixel ({mib:.1} MiB of samples); {shaded}", self.antialiasing.samples()))]
    }
}

#[cfg(test)]
mod tests {
    use super::{auto_antialiasing, Antialiasing};

    #[test]
    fn auto_takes_8_samples_on_a_gpu_the_next_it_takes_and_none_on_a_cpu() {
        use crate::error::SettingsError;
        let refuse =
            |aa: Antialiasing| Err(SettingsError::AntialiasingWithLayers { samples: aa.name(), technique: "forward", max: 8 }.into());
        assert_eq!(auto_antialiasing(true, |_| Ok(())).0, Antialiasing::Off);
        assert_eq!(auto_antialiasing(false, |_| Ok(())).0, Antialiasing::X8);
        let (aa, why) = auto_antialiasing(false, |aa| if aa == Antialiasing::X8 { refuse(aa) } else { Ok(()) });
        assert_eq!(aa, Antialiasing::X4);
        assert!(why.contains("not here") && why.contains("transparent"), "{why}");
        let (aa, why) = auto_antialiasing(false, refuse);
        assert_eq!(aa, Antialiasing::Off);
        assert!(why.contains("take no samples"), "{why}");
    }

    #[test]
    fn names_and_samples() {
        for aa in Antialiasing::ALL {
            assert_eq!(Antialiasing::from_name(aa.name()).ok(), Some(aa));
        }
        assert_eq!(Antialiasing::ALL.map(Antialiasing::samples), [1, 4, 8, 16]);
        assert!(Antialiasing::from_name("2").is_err());
        assert_eq!(Antialiasing::X8.buffer_bytes(1920, 1080), 1920 * 1080 * 64);
    }
}
