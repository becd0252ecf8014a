//! Procedural textures of the blinn-phong model's built-in scene (made by code, so the
//! repository ships no image files): an albedo of tiles, a normal map of round bumps, and a sky
//! cubemap for the environment reflection. RGBA8, every mip level made here (box filter).

use glam::{Vec2, Vec3};

/// An RGBA8 image and its mip chain (level 0 first, each half the size, down to 1×1).
#[derive(Clone, Debug, PartialEq)]
pub struct MipChain {
    pub size: u32,
    pub levels: Vec<Vec<u8>>,
}

/// A material texture of a scene (glTF): RGBA8 texels, row 0 at the top; `srgb` for colour
/// (the GPU decodes it), not for data such as normal maps; and how it is sampled. Textures of
/// one image share its texels (`rgba`, shared: an image under eight samplers is decoded,
/// held and uploaded once).
#[derive(Clone, Debug, PartialEq)]
pub struct TextureImage {
    pub width: u32,
    pub height: u32,
    pub rgba: std::sync::Arc<[u8]>,
    pub srgb: bool,
    pub sampler: TextureSampler,
}

/// How texture coordinates outside [0, 1] wrap (glTF's wrapS / wrapT).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    #[default]
    Repeat,
    MirroredRepeat,
    ClampToEdge,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Filter {
    Nearest,
    #[default]
    Linear,
}

/// A glTF sampler. The default (glTF leaves filters to the renderer): repeating, trilinear.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TextureSampler {
    pub wrap_u: Wrap,
    pub wrap_v: Wrap,
    pub mag: Filter,
    pub min: Filter,
    /// Between mip levels; None: the base level alone (glTF's NEAREST and LINEAR minFilter).
    pub mipmap: Option<Filter>,
}

impl Default for TextureSampler {
    fn default() -> TextureSampler {
        TextureSampler {
            wrap_u: Wrap::Repeat,
            wrap_v: Wrap::Repeat,
            mag: Filter::Linear,
            min: Filter::Linear,
            mipmap: Some(Filter::Linear),
        }
    }
}

impl TextureImage {
    /// Its mip chain, level 0 first, each level ⌊half⌋ the size (at least 1) down to 1×1; each
    /// texel the mean of the 2×2 texels above it (edges repeat at odd sizes), in linear light
    /// for sRGB images.
    pub fn mips(&self) -> Vec<Vec<u8>> {
        let to_linear = |c: u8| if self.srgb { srgb_to_linear(c as f32 / 255.0) } else { c as f32 / 255.0 };
        let from_linear = |v: f32| encode(if self.srgb { linear_to_srgb(v) } else { v });
        let (mut w, mut h) = (self.width, self.height);
        let mut level: Vec<[f32; 4]> =
            self.rgba.chunks_exact(4).map(|t| [to_linear(t[0]), to_linear(t[1]), to_linear(t[2]), t[3] as f32 / 255.0]).collect();
        let mut out = vec![self.rgba.to_vec()];
        while w > 1 || h > 1 {
            let (nw, nh) = ((w / 2).max(1), (h / 2).max(1));
            let at = |x: u32, y: u32| level[(y.min(h - 1) * w + x.min(w - 1)) as usize];
            let next: Vec<[f32; 4]> = (0..nw * nh)
                .map(|i| {
                    let (x, y) = (2 * (i % nw), 2 * (i / nw));
                    let quad = [at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)];
                    std::array::from_fn(|c| quad.iter().map(|t| t[c]).sum::<f32>() / 4.0)
                })
                .collect();
            out.push(next.iter().flat_map(|t| [from_linear(t[0]), from_linear(t[1]), from_linear(t[2]), encode(t[3])]).collect());
            (w, h, level) = (nw, nh, next);
        }
        out
    }
}

/// A normal-map texel (n·0.5 + 0.5 in its RGB) with its vector made unit length, to 8 bits
/// (no 8-bit texel decodes to zero: 2c − 255 is odd); alpha kept.
pub fn unit_normal_texel(t: [u8; 4]) -> [u8; 4] {
    let n = (Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0 * 2.0 - 1.0).normalize_or(Vec3::Z) * 0.5 + 0.5;
    [encode(n.x), encode(n.y), encode(n.z), t[3]]
}

fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.0031308 {
        v * 12.92
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Tiles per texture side of both maps (they line up: the bumps sit on the tiles).
pub const TILES: u32 = 4;

fn encode(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// Level 0 from `texel(u, v)` (texel-centre coordinates in [0, 1]), then the mips, each texel
/// the average of four (normal maps renormalise: `renormalise`).
fn build(size: u32, texel: impl Fn(Vec2) -> [f32; 4], renormalise: bool) -> MipChain {
    assert!(size.is_power_of_two());
    let mut level: Vec<[f32; 4]> = (0..size * size)
        .map(|i| texel(Vec2::new(((i % size) as f32 + 0.5) / size as f32, ((i / size) as f32 + 0.5) / size as f32)))
        .collect();
    let mut levels = Vec::new();
    let mut s = size;
    loop {
        levels.push(level.iter().flat_map(|t| t.map(encode)).collect());
        if s == 1 {
            break;
        }
        let half = s / 2;
        level = (0..half * half)
            .map(|i| {
                let (x, y) = (2 * (i % half), 2 * (i / half));
                let at = |dx: u32, dy: u32| level[((y + dy) * s + x + dx) as usize];
                let mut avg = [0.0; 4];
                for t in [at(0, 0), at(1, 0), at(0, 1), at(1, 1)] {
                    for c in 0..4 {
                        avg[c] += t[c] * 0.25;
                    }
                }
                if renormalise {
                    let n = (Vec3::new(avg[0], avg[1], avg[2]) * 2.0 - 1.0).normalize_or(Vec3::Z) * 0.5 + 0.5;
                    avg = [n.x, n.y, n.z, avg[3]];
                }
                avg
            })
            .collect();
        s = half;
    }
    MipChain { size, levels }
}

/// Where (u, v) is within its tile: (−1…1)² from the tile's centre.
fn in_tile(uv: Vec2) -> Vec2 {
    (uv * TILES as f32).fract() * 2.0 - 1.0
}

/// Grout lines between light and darker tiles, in a checkerboard.
pub fn tiles_albedo(size: u32) -> MipChain {
    build(
        size,
        |uv| {
            let p = in_tile(uv);
            if p.x.abs().max(p.y.abs()) > 0.9 {
                return [0.35, 0.33, 0.3, 1.0]; // grout
            }
            let cell = (uv * TILES as f32).floor();
            let dark = (cell.x + cell.y) as u32 % 2 == 1;
            if dark {
                [0.55, 0.42, 0.32, 1.0]
            } else {
                [0.92, 0.88, 0.8, 1.0]
            }
        },
        false,
    )
}

/// Height of the bump field at (u, v): a spherical cap in the middle of every tile.
pub fn bump_height(uv: Vec2) -> f32 {
    let r2 = in_tile(uv).length_squared() / 0.6f32.powi(2);
    if r2 < 1.0 {
        (1.0 - r2).sqrt()
    } else {
        0.0
    }
}

/// Tangent-space normals of the bumps (+z out of the surface, +x along u, +y along v),
/// encoded n·0.5 + 0.5.
pub fn bumps_normal_map(size: u32) -> MipChain {
    // Slope scale: the caps rise 0.03 texture units (a gentle relief).
    let rise = 0.03;
    let h = 0.5 / size as f32;
    build(
        size,
        |uv| {
            let dx = (bump_height(uv + Vec2::new(h, 0.0)) - bump_height(uv - Vec2::new(h, 0.0))) / (2.0 * h);
            let dy = (bump_height(uv + Vec2::new(0.0, h)) - bump_height(uv - Vec2::new(0.0, h))) / (2.0 * h);
            let n = Vec3::new(-dx * rise, -dy * rise, 1.0).normalize() * 0.5 + 0.5;
            [n.x, n.y, n.z, 1.0]
        },
        true,
    )
}

/// Direction through texel (x, y) of cube face `face` (+X, −X, +Y, −Y, +Z, −Z, Vulkan's order
/// and orientation).
pub fn cube_direction(face: u32, x: u32, y: u32, size: u32) -> Vec3 {
    let s = 2.0 * (x as f32 + 0.5) / size as f32 - 1.0;
    let t = 2.0 * (y as f32 + 0.5) / size as f32 - 1.0;
    match face {
        0 => Vec3::new(1.0, -t, -s),
        1 => Vec3::new(-1.0, -t, s),
        2 => Vec3::new(s, 1.0, t),
        3 => Vec3::new(s, -1.0, -t),
        4 => Vec3::new(s, -t, 1.0),
        _ => Vec3::new(-s, -t, -1.0),
    }
    .normalize()
}

/// Linear sky colour seen along `dir`: a blue gradient above the horizon, a dim ground below.
pub fn sky_colour(dir: Vec3) -> Vec3 {
    let up = dir.y;
    if up >= 0.0 {
        Vec3::new(0.75, 0.85, 1.0).lerp(Vec3::new(0.2, 0.4, 0.85), up.sqrt())
    } else {
        Vec3::new(0.3, 0.27, 0.22).lerp(Vec3::new(0.12, 0.1, 0.08), (-up).sqrt())
    }
}

/// The six faces of the sky cubemap (RGBA8, level 0 only: reflections sample it sharply).
pub fn sky_cube(size: u32) -> Vec<Vec<u8>> {
    (0..6)
        .map(|face| {
            (0..size * size)
                .flat_map(|i| {
                    let c = sky_colour(cube_direction(face, i % size, i / size, size));
                    [encode(c.x), encode(c.y), encode(c.z), 255]
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_texels_are_made_unit_length_keeping_their_direction() {
        let decode = |t: [u8; 4]| Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0 * 2.0 - 1.0;
        // Shorter than unit (as lossy maps store them), one leaning, one flat.
        for texel in [[128, 128, 250, 255], [90, 160, 230, 7], [128, 128, 255, 255]] {
            let unit = unit_normal_texel(texel);
            let (before, after) = (decode(texel), decode(unit));
            assert!((after.length() - 1.0).abs() < 0.0068, "{texel:?} -> {unit:?}: {}", after.length());
            assert!(after.normalize().dot(before.normalize()) > 0.9999, "{texel:?} -> {unit:?}");
            assert_eq!(unit[3], texel[3]);
        }
    }

    #[test]
    fn mip_chains_halve_down_to_one_texel() {
        let m = tiles_albedo(64);
        assert_eq!(m.levels.len(), 7);
        for (i, level) in m.levels.iter().enumerate() {
            assert_eq!(level.len(), ((64 >> i) * (64 >> i) * 4) as usize);
        }
    }

    #[test]
    fn bumps_lean_away_from_their_centres() {
        let m = bumps_normal_map(256);
        let texel = |u: f32, v: f32| {
            let (x, y) = ((u * 256.0) as usize, (v * 256.0) as usize);
            let t = &m.levels[0][(y * 256 + x) * 4..][..3];
            Vec3::new(t[0] as f32, t[1] as f32, t[2] as f32) / 255.0 * 2.0 - 1.0
        };
        // Tile (0, 0) spans u, v ∈ [0, 0.25]; its bump's centre is at 0.125.
        let right = texel(0.125 + 0.05, 0.125);
        let up = texel(0.125, 0.125 + 0.05);
        assert!(right.x > 0.05 && right.y.abs() < 0.02, "{right}");
        assert!(up.y > 0.05 && up.x.abs() < 0.02, "{up}");
        assert!(texel(0.01, 0.01).z > 0.99, "flat between bumps");
    }

    #[test]
    fn cube_faces_look_along_their_axes() {
        let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
        for (face, axis) in axes.iter().enumerate() {
            assert!(cube_direction(face as u32, 8, 8, 16).dot(*axis) > 0.99);
        }
        // +Y face: texel row 0 looks towards −Z (Vulkan's cube orientation).
        assert!(cube_direction(2, 8, 0, 16).z < -0.6);
        let sky = sky_cube(8);
        assert_eq!(sky.len(), 6);
        assert!(sky[2][2] > sky[3][2], "the sky above is bluer than the ground");
    }

    #[test]
    fn texture_mips_halve_down_to_one_texel_and_average_in_linear_light() {
        // 3×2: black and white columns; sRGB.
        let (b, w) = ([0u8, 0, 0, 255], [255u8, 255, 255, 255]);
        let rgba: Vec<u8> = [b, w, b, b, w, b].concat();
        let t = TextureImage { width: 3, height: 2, rgba: rgba.into(), srgb: true, sampler: TextureSampler::default() };
        let mips = t.mips();
        assert_eq!(mips.iter().map(Vec::len).collect::<Vec<_>>(), vec![24, 4]);
        // Level 1 (1×1) averages the top-left 2×2: half white in linear light is sRGB 188.
        assert_eq!(mips[1], vec![188, 188, 188, 255]);
        let data = TextureImage { srgb: false, ..t };
        assert_eq!(data.mips()[1], vec![128, 128, 128, 255]);
    }
}
