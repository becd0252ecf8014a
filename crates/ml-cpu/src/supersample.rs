//! Supersampled references (`render --supersample K`): an image rendered K times larger on
//! each axis, each K×K block filtered down to one pixel in the display's linear light — the
//! 8-bit values decoded by the renderer's gamma 2.2 (common.glsl encode_gamma), averaged,
//! encoded again. That is how the anti-aliased resolve averages a pixel's samples too
//! (docs/DESIGN.md#anti-aliasing), so the two converge as samples grow. And the measure the
//! tests and the docs compare images by: the RMS difference in 8-bit units.

/// The renderer's output curve (common.glsl encode_gamma).
const GAMMA: f32 = 2.2;

/// The image `rgba` (`width`×`height`, RGBA8) filtered down `k` times on each axis: each
/// k×k block's colour the mean of its pixels' in linear light, alpha the plain mean. `width`
/// and `height` must be multiples of `k`.
pub fn downsample(rgba: &[u8], (width, height): (u32, u32), k: u32) -> Vec<u8> {
    assert!(k >= 1 && width % k == 0 && height % k == 0, "{width}x{height} is not a multiple of {k}");
    assert_eq!(rgba.len(), width as usize * height as usize * 4, "RGBA8 of {width}x{height}");
    if k == 1 {
        // Decoding and encoding one sample gives every 8-bit value back (the test below).
        return rgba.to_vec();
    }
    let decode: Vec<f32> = (0..=255u8).map(|v| (f32::from(v) / 255.0).powf(GAMMA)).collect();
    let (w, h, k) = (width as usize / k as usize, height as usize / k as usize, k as usize);
    let samples = (k * k) as f32;
    let mut out = vec![0u8; w * h * 4];
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0f32; 4];
            for sy in 0..k {
                let row = ((y * k + sy) * width as usize + x * k) * 4;
                for p in rgba[row..row + k * 4].chunks_exact(4) {
                    for c in 0..3 {
                        sum[c] += decode[p[c] as usize];
                    }
                    sum[3] += f32::from(p[3]) / 255.0;
                }
            }
            let o = (y * w + x) * 4;
            for c in 0..3 {
                out[o + c] = ((sum[c] / samples).powf(1.0 / GAMMA) * 255.0).round().clamp(0.0, 255.0) as u8;
            }
            out[o + 3] = (sum[3] / samples * 255.0).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}

/// Root-mean-square difference of two RGBA8 images of one size over their colour channels,
/// in 8-bit units.
pub fn rms_difference(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "images of one size");
    let (mut sum, mut n) = (0f64, 0usize);
    for (pa, pb) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        for c in 0..3 {
            let d = f64::from(pa[c]) - f64::from(pb[c]);
            sum += d * d;
            n += 1;
        }
    }
    (sum / n.max(1) as f64).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_image_stays_what_it_was() {
        let rgba: Vec<u8> = [17u8, 128, 255, 255].repeat(6 * 4);
        assert_eq!(downsample(&rgba, (6, 4), 2), [17u8, 128, 255, 255].repeat(3 * 2));
        assert_eq!(downsample(&rgba, (6, 4), 1), rgba);
    }

    #[test]
    fn one_sample_decoded_and_encoded_is_the_value_it_was() {
        // What the filter makes of a block of one sample, which downsample(_, _, 1) skips.
        for v in 0..=255u8 {
            let linear = (f32::from(v) / 255.0).powf(GAMMA);
            assert_eq!((linear.powf(1.0 / GAMMA) * 255.0).round().clamp(0.0, 255.0) as u8, v);
            assert_eq!((f32::from(v) / 255.0 * 255.0).round() as u8, v);
        }
    }

    #[test]
    fn black_and_white_average_in_linear_light() {
        // Half white, half black: linear 0.5 is 0.5^(1/2.2) · 255 = 186, not 128.
        let mut rgba = Vec::new();
        for v in [255u8, 0, 0, 255] {
            rgba.extend([v, v, v, 255]);
        }
        assert_eq!(downsample(&rgba, (2, 2), 2), vec![186, 186, 186, 255]);
    }

    #[test]
    fn rms_in_eight_bit_units() {
        let a = [10u8, 10, 10, 255, 0, 0, 0, 0];
        let b = [13u8, 13, 13, 0, 0, 0, 0, 255];
        // Six channels, three of them 3 apart: sqrt(27 / 6).
        assert!((rms_difference(&a, &b) - (27.0f64 / 6.0).sqrt()).abs() < 1e-12);
        assert_eq!(rms_difference(&a, &a), 0.0);
    }
}
