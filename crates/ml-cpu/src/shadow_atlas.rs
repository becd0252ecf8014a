//! The shadow atlas's plan (docs/DESIGN.md#shadow-atlas), the CPU half: each frame, which cube
//! faces of which shadowed lights a visible pixel may sample, how many texels a side each gets,
//! and where each lies in one depth atlas of a fixed memory budget.
//!
//! - **Resolution** follows the light's size on screen: a face gets about as many texels a
//!   side as the light's sphere covers pixels across (a power of two, 32 … 2048), so a shadow
//!   texel is never much larger than a pixel of what it shades.
//! - **Faces** whose region (the face's 90° pyramid cut at the light's radius) lies wholly
//!   outside the view frustum get nothing: no visible pixel can sample them. The test is
//!   conservative — it keeps a face that might be sampled (the pyramid grown by a margin for
//!   PCF taps across a cube seam), never drops one that is.
//! - **The budget**: if the faces do not fit, every face's side is halved together (the same
//!   factor for every light: 1/2, 1/4 …, reported) until they do; none is dropped. If even
//!   32² faces do not fit, the plan fails with the numbers.
//! - **Packing**: square power-of-two tiles in a quadtree of blocks (a buddy allocator along
//!   the atlas's Z-order curve, whose texels are stored in that order too: a face is one run
//!   of memory). Laid out afresh, largest first, they fill the atlas with no gap — whatever
//!   fits by area fits.
//! - **Caching**: a face keeps its block from frame to frame while its size stays; it is
//!   drawn again only if its light moved (or the caller turns the cache off). When the kept
//!   blocks leave no room for the new ones, all are laid out afresh and drawn.

use crate::camera::{frustum_planes, Camera};
use crate::omni_shadow::face_axes;
use glam::{Vec3, Vec4};
use std::collections::{BTreeSet, HashMap};

/// Texels a side of the smallest and the largest face.
pub const MIN_FACE: u32 = 32;
pub const MAX_FACE: u32 = 2048;
/// Bytes per atlas texel (32-bit depth).
pub const TEXEL_BYTES: u64 = 4;
/// Bytes in a MiB (for messages).
const MIB: f64 = (1u64 << 20) as f64;
/// How far beyond its 90° pyramid a face is kept (in units of the distance along its axis):
/// the lookup's normal offset moves a point 1.5 texels, maybe across a seam into the
/// neighbouring face, and at the smallest face (32 texels, 16 a half-side) 2 texels are 1/8.
pub const SEAM_MARGIN: f32 = 0.125;

/// A shadowed light as the plan sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannedLight {
    pub position: Vec3,
    pub radius: f32,
}

/// One face's place in the atlas.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FaceTile {
    /// Index into the lights the plan was made for.
    pub light: u32,
    /// Cube face, in `omni_shadow::face_axes` order.
    pub face: u32,
    /// Texels a side.
    pub size: u32,
    /// Top-left texel in the atlas (its picture: the debug view).
    pub origin: [u32; 2],
    /// Index of its texel (0, 0) in the atlas's Z-ordered texels (`morton_encode`).
    pub base: u64,
    /// Whether this frame draws it (a new block, a moved light, or no cache).
    pub redraw: bool,
}

/// A frame's atlas: its layout and every face a visible pixel may sample.
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasPlan {
    pub blocks: AtlasBlocks,
    /// What every face's side was divided by to fit the budget (1: nothing).
    pub divided_by: u32,
    pub tiles: Vec<FaceTile>,
}

impl AtlasPlan {
    /// Faces this frame draws.
    pub fn redrawn(&self) -> usize {
        self.tiles.iter().filter(|t| t.redraw).count()
    }

    /// Bytes the tiles use (at most the atlas's, which is at most the budget).
    pub fn used_bytes(&self) -> u64 {
        self.tiles.iter().map(|t| t.size as u64 * t.size as u64 * TEXEL_BYTES).sum()
    }

    pub fn atlas_bytes(&self) -> u64 {
        self.blocks.texels() * TEXEL_BYTES
    }
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum AtlasError {
    #[error("a shadow budget of {bytes} bytes holds no {MIN_FACE}² face")]
    BudgetTooSmall { bytes: u64 },
    #[error(
        "{faces} shadow-cube faces need {:.1} MiB even at {MIN_FACE}² texels, more than the atlas's {:.1} MiB",
        *needed as f64 / MIB,
        *atlas as f64 / MIB
    )]
    TooManyFaces { faces: usize, needed: u64, atlas: u64 },
}

/// The texels a side a light's faces get: the pixels its sphere spans across a `height`-pixel
/// image (the eye inside it: the largest), rounded up to a power of two and clamped to
/// `MIN_FACE` … `MAX_FACE`. Orthographic cameras: the diameter over the view's height.
pub fn face_size(light: &PlannedLight, camera: &Camera, height: u32) -> u32 {
    let pixels = match camera.orthographic {
        Some(half_height) => light.radius / half_height * height as f32,
        None => {
            let d = light.position.distance(camera.position);
            if d <= light.radius {
                f32::INFINITY
            } else {
                // The sphere's angular radius, as a share of the half field of view.
                let half_angle = (light.radius / d).asin();
                half_angle.tan() / (camera.fov_y_deg.to_radians() * 0.5).tan() * height as f32
            }
        }
    };
    let pixels = pixels.clamp(MIN_FACE as f32, MAX_FACE as f32) as u32;
    pixels.next_power_of_two().min(MAX_FACE)
}

/// The faces (bit i: face i) of a light some point inside `planes` may sample: those whose
/// region — the face's pyramid, grown by `SEAM_MARGIN`, cut at the light's radius — is not
/// wholly outside one plane. The region lies inside the pyramid's apex and its base square at
/// the radius (every point of the sphere is within the radius along the axis), so those five
/// points decide.
pub fn visible_faces(light: &PlannedLight, planes: &[Vec4; 6]) -> u32 {
    let sphere_outside = planes.iter().any(|p| p.truncate().dot(light.position) + p.w < -light.radius);
    if sphere_outside {
        return 0;
    }
    let mut mask = 0;
    for face in 0..6 {
        let (forward, up) = face_axes(face);
        let side = forward.cross(up);
        let half = light.radius * (1.0 + SEAM_MARGIN);
        let base = light.position + forward * light.radius;
        let corners =
            [light.position, base + (side + up) * half, base + (side - up) * half, base - (side + up) * half, base - (side - up) * half];
        let outside = planes.iter().any(|p| corners.iter().all(|c| p.truncate().dot(*c) + p.w < 0.0));
        if !outside {
            mask |= 1 << face;
        }
    }
    mask
}

/// The atlas's layout: `count` square blocks of `side` texels (a power of two, at most
/// MAX_FACE), pictured `columns` across.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtlasBlocks {
    pub side: u32,
    pub count: u32,
    pub columns: u32,
}

impl AtlasBlocks {
    /// The most blocks `bytes` holds: MAX_FACE² ones, or below 16 MiB one block of the
    /// largest power-of-two side that fits.
    pub fn for_bytes(bytes: u64) -> Result<AtlasBlocks, AtlasError> {
        let texels = bytes / TEXEL_BYTES;
        if texels < (MIN_FACE * MIN_FACE) as u64 {
            return Err(AtlasError::BudgetTooSmall { bytes });
        }
        let side = (1u32 << ((texels as f64).sqrt().log2().floor() as u32)).min(MAX_FACE);
        // Texel indices are 32-bit on the GPU.
        let count = (texels / (side as u64 * side as u64)).min((1 << 32) / (side as u64 * side as u64)) as u32;
        Ok(AtlasBlocks { side, count, columns: (count as f64).sqrt().ceil() as u32 })
    }

    /// Texels across and down of the picture.
    pub fn extent(&self) -> [u32; 2] {
        [self.columns * self.side, self.count.div_ceil(self.columns) * self.side]
    }

    pub fn texels(&self) -> u64 {
        self.count as u64 * self.side as u64 * self.side as u64
    }
}

/// Where faces lie in the atlas, kept from frame to frame so that a face whose light did not
/// move keeps its texels (the cache): a quadtree of power-of-two blocks (a buddy allocator
/// over the atlas's Z-order), in units of one `MIN_FACE`² block.
#[derive(Clone, Debug)]
pub struct ShadowAtlas {
    blocks: AtlasBlocks,
    /// The order of the largest block (order k: (MIN_FACE·2^k)² texels).
    top: u32,
    /// Free blocks of each order, by first unit (lowest first: the layout is deterministic).
    free: Vec<BTreeSet<u64>>,
    /// Last frame's faces: (the caller's light key, face) → where, and the light as drawn.
    placed: HashMap<(u32, u32), Placement>,
}

#[derive(Clone, Copy, Debug)]
struct Placement {
    order: u32,
    unit: u64,
    drawn: PlannedLight,
}

/// Units (MIN_FACE² blocks) in a block of `order`.
fn order_units(order: u32) -> u64 {
    1 << (2 * order)
}

impl ShadowAtlas {
    /// An empty atlas of at most `bytes`.
    pub fn new(bytes: u64) -> Result<ShadowAtlas, AtlasError> {
        let blocks = AtlasBlocks::for_bytes(bytes)?;
        let top = (blocks.side / MIN_FACE).trailing_zeros();
        let mut atlas = ShadowAtlas { blocks, top, free: Vec::new(), placed: HashMap::new() };
        atlas.clear();
        Ok(atlas)
    }

    pub fn blocks(&self) -> AtlasBlocks {
        self.blocks
    }

    pub fn bytes(&self) -> u64 {
        self.blocks.texels() * TEXEL_BYTES
    }

    /// Forget every face (the casters changed): the next frame draws all of them.
    pub fn clear(&mut self) {
        self.placed.clear();
        self.free = vec![BTreeSet::new(); self.top as usize + 1];
        let step = order_units(self.top);
        self.free[self.top as usize] = (0..self.blocks.count as u64).map(|i| i * step).collect();
    }

    fn allocate(&mut self, order: u32) -> Option<u64> {
        let from = (order..=self.top).find(|&j| !self.free[j as usize].is_empty())?;
        let unit = self.free[from as usize].pop_first()?;
        // Split down: the block's first quarter goes on, the other three are free.
        for j in (order..from).rev() {
            for k in 1..4 {
                self.free[j as usize].insert(unit + k * order_units(j));
            }
        }
        Some(unit)
    }

    fn release(&mut self, mut unit: u64, mut order: u32) {
        while order < self.top {
            let parent = unit & !(order_units(order + 1) - 1);
            let siblings: Vec<u64> = (0..4).map(|k| parent + k * order_units(order)).filter(|&u| u != unit).collect();
            if !siblings.iter().all(|u| self.free[order as usize].contains(u)) {
                break;
            }
            for u in &siblings {
                self.free[order as usize].remove(u);
            }
            unit = parent;
            order += 1;
        }
        self.free[order as usize].insert(unit);
    }

    /// The frame's plan: every visible face of `lights` (each with the caller's key, which
    /// names the same light from frame to frame) seen by `camera` on a `width`×`height`
    /// image, at its size (`fixed`: every face that size instead), all halved together until
    /// they fit. A face keeps last frame's block if its size did not change; it is drawn again
    /// unless `cache` is on and its light is where it was drawn. When the kept blocks leave no
    /// room for the new ones, everything is laid out afresh (and drawn).
    pub fn plan(
        &mut self,
        lights: &[(u32, PlannedLight)],
        camera: &Camera,
        (width, height): (u32, u32),
        fixed: Option<u32>,
        cache: bool,
    ) -> Result<AtlasPlan, AtlasError> {
        let planes = frustum_planes(camera.projection(width as f32 / height as f32) * camera.view());
        let mut wanted = Vec::new();
        for (i, (_, light)) in lights.iter().enumerate() {
            let mask = visible_faces(light, &planes);
            let size = fixed.unwrap_or_else(|| face_size(light, camera, height)).clamp(MIN_FACE, MAX_FACE).next_power_of_two();
            wanted.extend((0..6).filter(|f| mask & (1 << f) != 0).map(|face| (i as u32, face, size)));
        }
        let capacity = self.blocks.texels();
        let area = |divisor: u32| wanted.iter().map(|&(_, _, s)| ((s / divisor).max(MIN_FACE) as u64).pow(2)).sum::<u64>();
        let mut divided_by = 1;
        while area(divided_by) > capacity {
            if MAX_FACE / divided_by <= MIN_FACE {
                let needed = wanted.len() as u64 * (MIN_FACE * MIN_FACE) as u64 * TEXEL_BYTES;
                return Err(AtlasError::TooManyFaces { faces: wanted.len(), needed, atlas: self.bytes() });
            }
            divided_by *= 2;
        }
        // Largest first (ties: light, face): a fresh layout in this order fills the Z-order
        // with no gap, so whatever fits by area fits.
        let mut tiles: Vec<FaceTile> = wanted
            .into_iter()
            .map(|(light, face, size)| FaceTile {
                light,
                face,
                size: (size / divided_by).max(MIN_FACE),
                origin: [0, 0],
                base: 0,
                redraw: true,
            })
            .collect();
        tiles.sort_by(|a, b| b.size.cmp(&a.size).then(a.light.cmp(&b.light)).then(a.face.cmp(&b.face)));
        let order_of = |t: &FaceTile| (t.size / MIN_FACE).trailing_zeros();
        let mut last = std::mem::take(&mut self.placed);
        let mut units = vec![None; tiles.len()];
        for (t, unit) in tiles.iter_mut().zip(&mut units) {
            let (key, light) = lights[t.light as usize];
            match last.remove(&(key, t.face)) {
                Some(p) if p.order == order_of(t) => {
                    *unit = Some(p.unit);
                    t.redraw = !cache || p.drawn != light;
                }
                Some(p) => self.release(p.unit, p.order),
                None => {}
            }
        }
        for p in last.into_values() {
            self.release(p.unit, p.order);
        }
        for (t, unit) in tiles.iter().zip(&mut units) {
            if unit.is_none() {
                *unit = self.allocate(order_of(t));
                if unit.is_none() {
                    break;
                }
            }
        }
        if units.iter().any(Option::is_none) {
            // The kept blocks split the free space too finely: lay everything out again.
            self.clear();
            for (t, unit) in tiles.iter_mut().zip(&mut units) {
                *unit = Some(self.allocate(order_of(t)).expect("faces that fit by area fit a fresh Z-order layout"));
                t.redraw = true;
            }
        }
        let per_block = order_units(self.top);
        let (side, columns) = (self.blocks.side as u64, self.blocks.columns as u64);
        for (t, unit) in tiles.iter_mut().zip(units) {
            let unit = unit.expect("every face placed");
            let (block, (x, y)) = (unit / per_block, morton_decode(unit % per_block));
            let corner = [(block % columns) * side, (block / columns) * side];
            t.origin = [(corner[0] + x * MIN_FACE as u64) as u32, (corner[1] + y * MIN_FACE as u64) as u32];
            t.base = unit * (MIN_FACE * MIN_FACE) as u64;
            let (key, drawn) = lights[t.light as usize];
            self.placed.insert((key, t.face), Placement { order: order_of(t), unit, drawn });
        }
        Ok(AtlasPlan { blocks: self.blocks, divided_by, tiles })
    }
}

/// Where texel (x, y) of a face lies in its block: the atlas holds its texels in Z-order
/// (Morton order: x in the even bits, y in the odd), so a face's texels are one run from its
/// `base`, and a 3×3 filter footprint mostly shares cache lines.
pub fn morton_encode(x: u32, y: u32) -> u64 {
    let spread = |v: u32| {
        let mut v = v as u64;
        v = (v | (v << 16)) & 0x0000_ffff_0000_ffff;
        v = (v | (v << 8)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v << 4)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v << 2)) & 0x3333_3333_3333_3333;
        (v | (v << 1)) & 0x5555_5555_5555_5555
    };
    spread(x) | (spread(y) << 1)
}

/// The (x, y) whose bits interleave (x in the even bits, y in the odd) to `index`.
fn morton_decode(index: u64) -> (u64, u64) {
    let compact = |mut v: u64| {
        v &= 0x5555_5555_5555_5555;
        v = (v | (v >> 1)) & 0x3333_3333_3333_3333;
        v = (v | (v >> 2)) & 0x0f0f_0f0f_0f0f_0f0f;
        v = (v | (v >> 4)) & 0x00ff_00ff_00ff_00ff;
        v = (v | (v >> 8)) & 0x0000_ffff_0000_ffff;
        (v | (v >> 16)) & 0x0000_0000_ffff_ffff
    };
    (compact(index), compact(index >> 1))
}

#[cfg(test)]
mod tests;
