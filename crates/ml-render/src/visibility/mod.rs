//! The visibility technique's GPU-driven geometry: the scene's meshlets, two-phase culling,
//! the visibility buffer drawn by the hardware or the compute raster, the depth pyramid, and
//! the lighting read from the visibility buffer (docs/DESIGN.md#visibility-buffer).

pub mod depth_pyramid;
pub mod meshlet_cull;
pub mod meshlet_scene;
pub mod triangle_raster_large;
pub mod visibility_gather;
pub mod visibility_lighting;
pub mod visibility_raster;

use crate::debug_view::{DebugView, Drawn, Legend, ViewNeed, ViewSpec};
use crate::feature::Feature;
use crate::technique::Technique;

const DRAWS_MESHLETS: ViewNeed = ViewNeed::Technique { what: "the technique drawn in meshlets", holds: Technique::draws_meshlets };

/// Surfaces shaded per pixel, as the lighting counts them in the 64-bit buffer (anti-aliased,
/// or from the compute and hybrid rasters): one blue, two cyan, three green, four yellow, five
/// and more red; the background as it is.
pub const SURFACES_VIEW: DebugView = DebugView {
    spec: &ViewSpec {
        name: "aa",
        code: ml_shaders::debug_view::AA,
        needs: &[DRAWS_MESHLETS, ViewNeed::SampleBuffer],
        drawn: Drawn::InShading { toned: false, layers: false },
        legend: Legend::Text("surfaces shaded per pixel: blue 1, cyan 2, green 3, yellow 4, red 5 or more"),
    },
};

/// A colour per meshlet instance, and per triangle; the surfaces a pixel shades.
pub(crate) const VIEWS: &[DebugView] = {
    use ml_shaders::debug_view as code;
    const fn colours(name: &'static str, code: u32) -> ViewSpec {
        ViewSpec::plain(name, code, &[DRAWS_MESHLETS], Drawn::InShading { toned: false, layers: false })
    }
    &[DebugView { spec: &colours("meshlets", code::MESHLETS) }, DebugView { spec: &colours("triangles", code::TRIANGLES) }, SURFACES_VIEW]
};

/// The visibility technique as a feature (the assembly's list): its views.
pub const FEATURE: Feature = Feature::views(VIEWS);
