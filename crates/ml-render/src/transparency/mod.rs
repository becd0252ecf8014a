//! Transparency (glTF `alphaMode: BLEND`): the transparent objects' fragments in front of the
//! opaque surfaces kept per pixel in linked lists (`transparent_build`), then lit a node at a
//! time and blended back to front over the opaque pass's linear HDR output
//! (`transparent_resolve`), in every technique. The rule a pixel follows, and its reference,
//! is ml-cpu `transparency`; the shaders are under `shaders/transparency/`.
//!
//! Memory is a fixed budget set by an option: a pool of nodes, `budget` per pixel on average,
//! and a head per pixel. What does not fit is counted and reported, never silently lost:
//! fragments that find the pool full are dropped, and pixels with more than `LAYER_KEEP`
//! layers merge their farthest ones (`TransparencyStats`).

mod layer_buffers;
pub mod transparent_build;
pub mod transparent_resolve;

use crate::debug_view::{DebugView, Drawn, ViewNeed, ViewSpec};
use crate::error::{RenderError, Setting, SettingsError};
use crate::report::FeatureStats;
use crate::sync::Use;
pub use layer_buffers::{node_bytes, LayerBuffers, LAYER_BUFFERS};
use ml_vk::{vk, Context};

/// Transparent layers per pixel as a heat map up to the `LAYER_KEEP` a pixel blends exactly;
/// white where more were merged.
pub const LAYERS_VIEW: DebugView = DebugView {
    spec: &ViewSpec::plain(
        "transparency-layers",
        ml_shaders::debug_view::TRANSPARENCY_LAYERS,
        &[ViewNeed::TransparentObjects],
        Drawn::InShading { toned: false, layers: true },
    ),
};

pub(crate) const VIEWS: &[DebugView] = &[LAYERS_VIEW];

/// A list's end (layers.glsl LAYER_END): what the heads are cleared to.
pub const LAYER_END: u32 = 0xffff_ffff;
/// Layers a pixel blends exactly (layers.glsl LAYER_KEEP); farther ones are merged.
pub const LAYER_KEEP: u32 = 32;
/// The most samples a pixel's layers keep their coverage of with anti-aliasing (layers.glsl
/// LAYER_MAX_SAMPLES: a bit each in a node's object word).
pub const LAYER_MAX_SAMPLES: u32 = 8;
/// Nodes per pixel on average, unless the option says otherwise.
pub const DEFAULT_BUDGET: u32 = 4;
/// The most nodes per pixel the option takes.
pub const MAX_BUDGET: u32 = 256;

/// How transparent objects are drawn: the node pool's size, in nodes per pixel on average,
/// and which objects the build draws over tiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TransparencySettings {
    pub budget: u32,
    /// Objects of at most this many triangles are built over tiles, the others a thread per
    /// triangle (`transparent_build`; the same fragments either way, which tests check by
    /// moving this bound).
    pub tiled_up_to: u32,
    /// The scene's PBR extensions vary per point, so nodes keep their texels too
    /// (`node_bytes`; settled by the renderer from the scene).
    pub lobe_textures: bool,
    /// Without anti-aliasing, the compute raster lists the soft samples of transparent
    /// objects' cores for the layers (transparent_build_candidates.glsl), its list holding
    /// this many at first (it grows after a frame that listed more; 0: it lists none, and the
    /// per-triangle build takes the cores, as with samples).
    pub candidate_list: u32,
}

/// Layer candidates the compute raster's list holds at first (16 MiB).
pub const DEFAULT_CANDIDATE_LIST: u32 = 1 << 20;

impl Default for TransparencySettings {
    fn default() -> Self {
        TransparencySettings {
            budget: DEFAULT_BUDGET,
            tiled_up_to: crate::gpu_mesh::COMPUTE_LAYER_TRIANGLES,
            lobe_textures: false,
            candidate_list: DEFAULT_CANDIDATE_LIST,
        }
    }
}

impl TransparencySettings {
    /// Nodes of the pool at `width`×`height`.
    pub fn nodes(&self, width: u32, height: u32) -> u64 {
        width as u64 * height as u64 * self.budget as u64
    }

    /// The budget in range, and the pool one storage buffer the device binds.
    pub fn check(&self, ctx: &Context, width: u32, height: u32) -> Result<(), RenderError> {
        if self.budget == 0 || self.budget > MAX_BUDGET {
            return Err(SettingsError::OutOfRange { what: Setting::TransparencyBudget, value: self.budget, max: MAX_BUDGET }.into());
        }
        let bytes = self.nodes(width, height) * node_bytes(self.lobe_textures);
        let max = ctx.info.limits.max_storage_buffer_range;
        if bytes > max as u64 {
            let budget = self.budget;
            return Err(SettingsError::TransparencyPool { budget, width, height, bytes, device: ctx.info.name.clone(), max }.into());
        }
        Ok(())
    }
}

/// How the resolve uses the lists (`Pass::uses`): reads the heads, lights the nodes in place,
/// counts the pixels that merged layers.
pub fn layer_uses(stages: vk::PipelineStageFlags) -> Vec<Use> {
    let read = (stages, vk::AccessFlags::SHADER_READ);
    let read_write = (stages, vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE);
    vec![Use::buffer(LAYER_BUFFERS[0], read), Use::buffer(LAYER_BUFFERS[1], read_write), Use::buffer(LAYER_BUFFERS[2], read_write)]
}

/// The transparent layers of the last frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TransparencyStats {
    /// Transparent fragments in front of the opaque surfaces (kept or dropped).
    pub fragments: u64,
    /// Nodes the pool holds, of `node_bytes` each.
    pub capacity: u64,
    pub node_bytes: u64,
    /// Pixels of the image.
    pub pixels: u64,
    /// Pixels with more than `LAYER_KEEP` layers, whose farthest ones were merged.
    pub merged_pixels: u64,
    /// Triangles of the objects built a thread per triangle that were too large for a
    /// thread: built by a work group each, and (larger still) over the tiles.
    pub group_triangles: u64,
    pub tiled_triangles: u64,
}

impl TransparencyStats {
    /// Fragments the full pool dropped.
    pub fn dropped(&self) -> u64 {
        self.fragments.saturating_sub(self.capacity)
    }

    /// Bytes per pixel of the lists (heads and the pool).
    pub fn bytes_per_pixel(&self) -> f64 {
        4.0 + (self.capacity * self.node_bytes) as f64 / self.pixels.max(1) as f64
    }

    /// Whether something was dropped or merged (the frame is not exact).
    pub fn overflowed(&self) -> bool {
        self.dropped() > 0 || self.merged_pixels > 0
    }

    /// What a user is told when the frame is not exact: what was dropped and what merged,
    /// each only where it happened (None when neither did).
    pub fn overflow_warning(&self) -> Option<String> {
        let mut parts = Vec::new();
        if self.dropped() > 0 {
            parts.push(format!(
                "{} fragments dropped, the pool of {} nodes full (raise --transparency-budget)",
                self.dropped(),
                self.capacity
            ));
        }
        if self.merged_pixels > 0 {
            parts.push(format!(
                "{} pixels had more than {LAYER_KEEP} layers, the farthest merged into one layer behind the nearest {LAYER_KEEP} (their order lost)",
                self.merged_pixels
            ));
        }
        (!parts.is_empty()).then(|| format!("the transparent layers are not exact: {}", parts.join("; ")))
    }
}

impl FeatureStats for TransparencyStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let s = self;
        vec![
            (
                "transparent layers",
                format!(
                    "{} fragments ({:.2} a pixel), pool {} nodes ({:.0} B/pixel with heads)",
                    s.fragments,
                    s.fragments as f64 / s.pixels.max(1) as f64,
                    s.capacity,
                    s.bytes_per_pixel()
                ),
            ),
            (
                "transparent overflow",
                format!(
                    "{} fragments dropped (pool full), {} pixels over {LAYER_KEEP} layers (the farthest merged)",
                    s.dropped(),
                    s.merged_pixels
                ),
            ),
            (
                "transparent build",
                format!(
                    "{} triangles too large for a thread: {} by a work group each, {} over tiles",
                    s.group_triangles + s.tiled_triangles,
                    s.group_triangles,
                    s.tiled_triangles
                ),
            ),
        ]
    }
}
