//! Alpha masks (glTF `alphaMode: MASK`, and `BLEND` where it is drawn as a mask: shadows): which points of a
//! surface are there. A point's alpha is the base colour factor's alpha times the base colour
//! texture's alpha at its texture coordinates; below the material's cutoff the point is cut
//! out — no colour, no depth, no shadow.
//!
//! Every pass that decides coverage asks the same question the same way: the fragment shaders
//! (forward, G-buffer, the hardware visibility raster, the shadow passes) and the compute
//! rasterisers alike, which draw triangles of many objects in one dispatch and so cannot bind
//! each object's texture. So the alpha of every texture a masked object cuts with is copied,
//! one byte a texel (base level), into one storage buffer, and one function
//! (`shaders/common/alpha_mask.glsl`, its CPU twin `texture_alpha` here) filters it by hand
//! with the texture's wrap modes: bilinear, or nearest where the sampler magnifies that way.
//! The base level everywhere, rather than a mip chosen per pixel, so that the techniques and
//! the shadows cut exactly the same shape (mips would thin foliage with distance, and each
//! raster would choose its level from derivatives of its own).
//!
//! Most points of a cut-out texture lie well inside or well outside its shape, so after each
//! texture's texels come the alpha bounds of its 2×2-texel blocks (larger in large textures): the least and the greatest
//! alpha of the texels any filter tap at a point of the block can read (the block grown by a
//! texel each way, wrapped as the texture wraps). A filtered alpha lies between its taps, so
//! where the bounds are both on one side of the cutoff the answer is known from one read;
//! only points near the shape's edge are filtered.

use crate::gpu_types::{
    OBJECT_ALPHA_BLOCK_SHIFT, OBJECT_ALPHA_NEAREST, OBJECT_ALPHA_TEXTURE, OBJECT_ALPHA_WRAP_SHIFT, OBJECT_BLENDED, OBJECT_CORE,
    OBJECT_DOUBLE_SIDED, OBJECT_MASKED,
};
use crate::scene::{Object, Scene};
use crate::textures::{Filter, TextureImage, Wrap};
use glam::Vec2;
use std::collections::HashMap;

/// Texels a side of the blocks whose alpha bounds are kept: at least this, and doubled until
/// the texture has at most MAX_BLOCKS of them. Small blocks decide more points (a point is
/// filtered only where its block, grown by a texel, holds the shape's edge): on the H100 a
/// forest of 128²-texel leaves rasterised 1.5 % faster with 2×2 blocks than with 4×4, its
/// shadows 3.5 %. The bounds take half the texels' bytes then.
pub const ALPHA_BLOCK: i64 = 2;
/// Most blocks a texture's bounds have (128 KiB of bounds: larger textures get larger blocks).
pub const MAX_BLOCKS: i64 = 65536;

/// Most bytes of alpha texels (offsets are 32-bit; the device's storage-buffer range may
/// allow less, which the renderer checks).
pub const MAX_ALPHA_BYTES: u64 = 1 << 31;

/// The alpha of every texture a masked object cuts with, packed for the GPU.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AlphaMasks {
    /// Each packed texture's alpha bytes, row by row, textures back to back, four bytes to a
    /// word (the first in the low byte).
    pub words: Vec<u32>,
    /// Scene texture → where its alpha starts (bytes).
    first: HashMap<u32, u32>,
}

/// Why the alpha masks cannot be packed.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the masked materials' textures need {bytes} bytes of alpha, more than the {max} one buffer holds", max = MAX_ALPHA_BYTES)]
pub struct TooMuchAlpha {
    pub bytes: u64,
}

impl AlphaMasks {
    /// The alpha of every base colour texture that a masked (or blended) object of `scene`
    /// uses, each once.
    pub fn pack(scene: &Scene) -> Result<AlphaMasks, TooMuchAlpha> {
        let mut masks = AlphaMasks::default();
        let mut bytes: Vec<u8> = Vec::new();
        for o in scene.objects.iter().filter(|o| o.extras.masked()) {
            let Some(t) = o.textures.base_color else { continue };
            let Some(image) = scene.textures.get(t as usize) else { continue };
            if masks.first.contains_key(&t) {
                continue;
            }
            let texels = image.width as u64 * image.height as u64;
            let total = bytes.len() as u64 + texels.next_multiple_of(2) + 2 * block_count(image);
            if total > MAX_ALPHA_BYTES {
                return Err(TooMuchAlpha { bytes: total });
            }
            masks.first.insert(t, bytes.len() as u32);
            bytes.extend(image.rgba.chunks_exact(4).map(|p| p[3]));
            // The block bounds start at an even byte (a pair never straddles a word).
            bytes.resize(bytes.len().next_multiple_of(2), 0);
            let (bw, bh) = blocks(image);
            for by in 0..bh {
                for bx in 0..bw {
                    let (lo, hi) = block_bounds(image, bx, by);
                    bytes.extend([lo, hi]);
                }
            }
        }
        bytes.resize(bytes.len().next_multiple_of(4).max(4), 0);
        masks.words = bytes.chunks_exact(4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]])).collect();
        Ok(masks)
    }

    /// Object `o`'s `ObjectData::alpha` and `alpha_texture` (`textures`: the scene's).
    pub fn object_fields(&self, o: &Object, textures: &[TextureImage]) -> ([f32; 4], [u32; 4]) {
        let x = &o.extras;
        let mut flags = 0;
        if x.double_sided {
            flags |= OBJECT_DOUBLE_SIDED;
        }
        if x.transparent() {
            flags |= OBJECT_BLENDED;
        }
        if x.has_core() {
            flags |= OBJECT_CORE;
        }
        let Some(cutoff) = x.alpha_mode.cutoff() else {
            // OPAQUE: the alpha is ignored (a transmitting surface's layers cover their pixel).
            return ([0.0, 1.0, 0.0, 0.0], [flags, 0, 0, 0]);
        };
        flags |= OBJECT_MASKED;
        let texture = o.textures.base_color.and_then(|t| Some((textures.get(t as usize)?, *self.first.get(&t)?)));
        let Some((image, first)) = texture else {
            return ([cutoff, x.base_alpha, 0.0, 0.0], [flags, 0, 0, 0]);
        };
        flags |= OBJECT_ALPHA_TEXTURE
            | wrap_code(image.sampler.wrap_u) << OBJECT_ALPHA_WRAP_SHIFT
            | wrap_code(image.sampler.wrap_v) << (OBJECT_ALPHA_WRAP_SHIFT + 2);
        if image.sampler.mag == Filter::Nearest {
            flags |= OBJECT_ALPHA_NEAREST;
        }
        flags |= block_side(image).trailing_zeros() << OBJECT_ALPHA_BLOCK_SHIFT;
        ([cutoff, x.base_alpha, 0.0, 0.0], [flags, first, image.width, image.height])
    }
}

/// The side of `t`'s blocks: ALPHA_BLOCK, doubled until they are at most MAX_BLOCKS.
fn block_side(t: &TextureImage) -> i64 {
    let mut side = ALPHA_BLOCK;
    while ((t.width as i64 + side - 1) / side) * ((t.height as i64 + side - 1) / side) > MAX_BLOCKS {
        side *= 2;
    }
    side
}

/// Blocks a row and a column of `t` has.
fn blocks(t: &TextureImage) -> (i64, i64) {
    let side = block_side(t);
    ((t.width as i64 + side - 1) / side, (t.height as i64 + side - 1) / side)
}

fn block_count(t: &TextureImage) -> u64 {
    let (bw, bh) = blocks(t);
    (bw * bh) as u64
}

/// The least and greatest alpha of the texels a filter tap at a point of block (bx, by) can
/// read: the block's texels and one more each way, wrapped.
fn block_bounds(t: &TextureImage, bx: i64, by: i64) -> (u8, u8) {
    let (w, h, side) = (t.width as i64, t.height as i64, block_side(t));
    let (mut lo, mut hi) = (u8::MAX, u8::MIN);
    for y in by * side - 1..=by * side + side {
        for x in bx * side - 1..=bx * side + side {
            let (x, y) = (wrap_texel(x, w, t.sampler.wrap_u), wrap_texel(y, h, t.sampler.wrap_v));
            let a = t.rgba[((y * w + x) * 4 + 3) as usize];
            (lo, hi) = (lo.min(a), hi.max(a));
        }
    }
    (lo, hi)
}

/// Where the point at `uv` reads its first tap (the nearest texel, or the filter's top-left
/// one), wrapped: the block it is in decides.
fn first_tap(t: &TextureImage, uv: Vec2) -> (i64, i64) {
    let p = uv * Vec2::new(t.width as f32, t.height as f32) - 0.5;
    let f = if t.sampler.mag == Filter::Nearest { (p + 0.5).floor() } else { p.floor() };
    (wrap_texel(f.x as i64, t.width as i64, t.sampler.wrap_u), wrap_texel(f.y as i64, t.height as i64, t.sampler.wrap_v))
}

/// Whether `factor` × the texture's alpha at `uv` reaches `cutoff`: from the bounds of the
/// point's block where they decide, else by filtering. Keep in sync with alpha_mask.glsl
/// `texture_kept`.
fn texture_kept(t: &TextureImage, uv: Vec2, factor: f32, cutoff: f32) -> bool {
    let (x, y) = first_tap(t, uv);
    let side = block_side(t);
    let (lo, hi) = block_bounds(t, x / side, y / side);
    if factor * (lo as f32 / 255.0) >= cutoff {
        return true;
    }
    if factor * (hi as f32 / 255.0) < cutoff {
        return false;
    }
    factor * texture_alpha(t, uv) >= cutoff
}

/// A wrap mode as alpha_mask.glsl reads it.
fn wrap_code(w: Wrap) -> u32 {
    match w {
        Wrap::Repeat => 0,
        Wrap::MirroredRepeat => 1,
        Wrap::ClampToEdge => 2,
    }
}

/// Texel `i` of a row or column of `size` texels under wrap mode `w`. Keep in sync with
/// alpha_mask.glsl `wrap_texel`.
fn wrap_texel(i: i64, size: i64, w: Wrap) -> i64 {
    match w {
        Wrap::Repeat => i.rem_euclid(size),
        Wrap::MirroredRepeat => {
            let m = i.rem_euclid(2 * size);
            if m < size {
                m
            } else {
                2 * size - 1 - m
            }
        }
        Wrap::ClampToEdge => i.clamp(0, size - 1),
    }
}

/// The texture's alpha at `uv` as the shaders filter it: its base level, bilinear (nearest
/// where it magnifies nearest), with its wrap modes. Keep in sync with alpha_mask.glsl
/// `texture_alpha`.
pub fn texture_alpha(t: &TextureImage, uv: Vec2) -> f32 {
    let (w, h) = (t.width as i64, t.height as i64);
    let texel = |x: i64, y: i64| {
        let (x, y) = (wrap_texel(x, w, t.sampler.wrap_u), wrap_texel(y, h, t.sampler.wrap_v));
        t.rgba[((y * w + x) * 4 + 3) as usize] as f32 / 255.0
    };
    let p = uv * Vec2::new(w as f32, h as f32) - 0.5;
    if t.sampler.mag == Filter::Nearest {
        let n = (p + 0.5).floor();
        return texel(n.x as i64, n.y as i64);
    }
    let f0 = p.floor();
    let f = p - f0;
    let (x, y) = (f0.x as i64, f0.y as i64);
    let top = texel(x, y) * (1.0 - f.x) + texel(x + 1, y) * f.x;
    let bottom = texel(x, y + 1) * (1.0 - f.x) + texel(x + 1, y + 1) * f.x;
    top * (1.0 - f.y) + bottom * f.y
}

/// Whether the point of object `o` at mesh texture coordinates `uv` (before its texture
/// transform) is there (not cut out); `textures`: the scene's.
pub fn kept(o: &Object, textures: &[TextureImage], uv: Vec2) -> bool {
    let Some(cutoff) = o.extras.alpha_mode.cutoff() else { return true };
    match o.textures.base_color.and_then(|t| textures.get(t as usize)) {
        Some(t) => texture_kept(t, o.extras.uv_transform.transform_point2(uv), o.extras.base_alpha, cutoff),
        None => o.extras.base_alpha >= cutoff,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::material::Material;
    use crate::mesh::MeshKind;
    use crate::scene::{AlphaMode, MaterialExtras, ObjectTextures};
    use crate::textures::TextureSampler;

    /// A 4×2 texture whose alpha is 0, 85, 170, 255 along each row.
    fn ramp(sampler: TextureSampler) -> TextureImage {
        let rgba: Vec<u8> = (0..8).flat_map(|i| [9, 9, 9, (i % 4) as u8 * 85]).collect();
        TextureImage { width: 4, height: 2, rgba: rgba.into(), srgb: true, sampler }
    }

    fn masked(texture: Option<u32>, alpha_mode: AlphaMode) -> Object {
        let mut o = Object::placed(MeshKind::Plane, glam::Vec3::ZERO, 1.0, Material::named("white").unwrap());
        o.textures = ObjectTextures { base_color: texture, ..ObjectTextures::default() };
        o.extras = MaterialExtras { alpha_mode, base_alpha: 0.8, ..MaterialExtras::default() };
        o
    }

    #[test]
    fn bilinear_alpha_at_texel_centres_and_between() {
        let t = ramp(TextureSampler::default());
        // Texel centres: (i + 0.5) / 4.
        for i in 0..4 {
            let a = texture_alpha(&t, Vec2::new((i as f32 + 0.5) / 4.0, 0.25));
            assert!((a - i as f32 / 3.0).abs() < 1e-6, "texel {i}: {a}");
        }
        // Halfway between texels 1 and 2.
        assert!((texture_alpha(&t, Vec2::new(0.5, 0.25)) - 0.5).abs() < 1e-6);
        // Repeat: the left edge blends the last texel with the first.
        assert!((texture_alpha(&t, Vec2::new(0.0, 0.25)) - 0.5).abs() < 1e-6);
        assert!((texture_alpha(&t, Vec2::new(1.0, 0.25)) - 0.5).abs() < 1e-6);
        let clamped = ramp(TextureSampler { wrap_u: Wrap::ClampToEdge, ..TextureSampler::default() });
        assert_eq!(texture_alpha(&clamped, Vec2::new(0.0, 0.25)), 0.0);
        assert_eq!(texture_alpha(&clamped, Vec2::new(-3.0, 0.25)), 0.0);
        assert_eq!(texture_alpha(&clamped, Vec2::new(7.0, 0.25)), 1.0);
        let mirrored = ramp(TextureSampler { wrap_u: Wrap::MirroredRepeat, ..TextureSampler::default() });
        // Just past the right edge the mirror repeats the last texel, then runs back.
        assert_eq!(texture_alpha(&mirrored, Vec2::new(1.0 + 0.5 / 4.0, 0.25)), 1.0);
        assert!((texture_alpha(&mirrored, Vec2::new(1.0 + 1.5 / 4.0, 0.25)) - 2.0 / 3.0).abs() < 1e-6);
        let nearest = ramp(TextureSampler { mag: Filter::Nearest, ..TextureSampler::default() });
        assert_eq!(texture_alpha(&nearest, Vec2::new(0.49, 0.25)), 1.0 / 3.0);
        assert_eq!(texture_alpha(&nearest, Vec2::new(0.51, 0.25)), 2.0 / 3.0);
    }

    #[test]
    fn block_bounds_decide_as_the_filter_would() {
        // A disc of alpha 255 in a 32×32 texture of 0: inside and outside blocks are decided
        // by their bounds; every point, decided or filtered, gets the filter's answer.
        let n = 32u32;
        let rgba: Vec<u8> = (0..n * n)
            .flat_map(|i| {
                let (x, y) = ((i % n) as f32 - 15.5, (i / n) as f32 - 15.5);
                [0, 0, 0, if x * x + y * y < 50.0 { 255 } else { 0 }]
            })
            .collect();
        for wrap in [Wrap::Repeat, Wrap::MirroredRepeat, Wrap::ClampToEdge] {
            for mag in [Filter::Linear, Filter::Nearest] {
                let sampler = TextureSampler { wrap_u: wrap, wrap_v: wrap, mag, ..TextureSampler::default() };
                let t = TextureImage { width: n, height: n, rgba: rgba.clone().into(), srgb: false, sampler };
                assert_eq!(block_side(&t), 2);
                assert_eq!(block_bounds(&t, 7, 7), (255, 255));
                assert_eq!(block_bounds(&t, 4, 7), (0, 255));
                assert_eq!(block_bounds(&t, 0, 0), (0, 0));
                for k in 0..4000 {
                    let uv = Vec2::new((k % 80) as f32 / 40.0 - 0.5, (k / 80) as f32 / 25.0 - 0.5) * 0.6 + 0.2;
                    for cutoff in [0.3, 0.5, 0.9] {
                        let filtered = if mag == Filter::Nearest {
                            let (x, y) = first_tap(&t, uv);
                            t.rgba[((y * n as i64 + x) * 4 + 3) as usize] as f32 / 255.0
                        } else {
                            texture_alpha(&t, uv)
                        };
                        assert_eq!(texture_kept(&t, uv, 0.9, cutoff), 0.9 * filtered >= cutoff, "{wrap:?} {mag:?} {uv} {cutoff}");
                    }
                }
            }
        }
    }

    #[test]
    fn large_textures_get_larger_blocks() {
        let t = |width, height| TextureImage { width, height, rgba: Vec::new().into(), srgb: false, sampler: TextureSampler::default() };
        assert_eq!(block_side(&t(512, 512)), 2); // 256² = 65,536 blocks
        assert_eq!(block_side(&t(514, 514)), 4);
        assert_eq!(block_side(&t(2048, 2048)), 8);
        assert_eq!(block_side(&t(16384, 1)), 2);
    }

    #[test]
    fn masks_cut_by_factor_times_texture_alpha() {
        let textures = vec![ramp(TextureSampler::default())];
        let o = masked(Some(0), AlphaMode::Mask { cutoff: 0.5 });
        // 0.8 × 2/3 = 0.53 ≥ 0.5 is kept; 0.8 × 1/3 = 0.27 is not.
        assert!(kept(&o, &textures, Vec2::new(2.5 / 4.0, 0.5)));
        assert!(!kept(&o, &textures, Vec2::new(1.5 / 4.0, 0.5)));
        // Without a texture the factor alone decides.
        assert!(kept(&masked(None, AlphaMode::Mask { cutoff: 0.8 }), &textures, Vec2::ZERO));
        assert!(!kept(&masked(None, AlphaMode::Mask { cutoff: 0.81 }), &textures, Vec2::ZERO));
        // Blend is a mask at one half; opaque keeps everything.
        assert!(!kept(&masked(Some(0), AlphaMode::Blend), &textures, Vec2::new(1.5 / 4.0, 0.5)));
        assert!(kept(&masked(Some(0), AlphaMode::Opaque), &textures, Vec2::new(0.5 / 4.0, 0.5)));
    }

    #[test]
    fn only_masked_objects_textures_are_packed_each_once() {
        let mut scene = Scene::new(Vec::new(), Vec::new(), Camera::seed());
        scene.textures = vec![ramp(TextureSampler::default()), ramp(TextureSampler { wrap_v: Wrap::ClampToEdge, ..Default::default() })];
        scene.objects = vec![
            masked(Some(1), AlphaMode::Mask { cutoff: 0.3 }),
            masked(Some(0), AlphaMode::Opaque),
            masked(Some(1), AlphaMode::Blend),
            masked(None, AlphaMode::Mask { cutoff: 0.5 }),
        ];
        let masks = AlphaMasks::pack(&scene).unwrap();
        // Texture 1 alone: 8 alpha bytes, then its two blocks' bounds, (0, 255) each.
        assert_eq!(masks.words, vec![0xff_aa_55_00, 0xff_aa_55_00, 0xff_00_ff_00]);
        let (alpha, fields) = masks.object_fields(&scene.objects[0], &scene.textures);
        assert_eq!(alpha, [0.3, 0.8, 0.0, 0.0]);
        let block = 1 << OBJECT_ALPHA_BLOCK_SHIFT; // 2 texels
        assert_eq!(fields, [OBJECT_MASKED | OBJECT_ALPHA_TEXTURE | 2 << (OBJECT_ALPHA_WRAP_SHIFT + 2) | block, 0, 4, 2]);
        assert_eq!(masks.object_fields(&scene.objects[1], &scene.textures).1, [0, 0, 0, 0]);
        assert_eq!(
            masks.object_fields(&scene.objects[2], &scene.textures).1[0] & (OBJECT_BLENDED | OBJECT_MASKED),
            OBJECT_BLENDED | OBJECT_MASKED
        );
        assert_eq!(masks.object_fields(&scene.objects[3], &scene.textures), ([0.5, 0.8, 0.0, 0.0], [OBJECT_MASKED, 0, 0, 0]));
        // A core (points of alpha 1 drawn as opaque) only where its alpha can reach 1 and it
        // transmits nothing.
        let core = |o: &Object| masks.object_fields(o, &scene.textures).1[0] & OBJECT_CORE != 0;
        let mut blended = scene.objects[2];
        assert!(!core(&blended), "alpha factor 0.8");
        blended.extras.base_alpha = 1.0;
        assert!(core(&blended));
        blended.extras.lobes.transmission = 0.5;
        assert!(!core(&blended), "transmitting");
        // Nothing masked: one word the shaders never read.
        scene.objects.truncate(2);
        scene.objects.remove(0);
        assert_eq!(AlphaMasks::pack(&scene).unwrap().words, vec![0]);
    }
}
