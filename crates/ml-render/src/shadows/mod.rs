//! Shadows: the stores (stores.rs, one interface over the point lights' cube array and
//! atlas, the sun's map and the shadow rays' hierarchy), their settings, the compute shadow
//! raster, and the passes that draw the shadowed lights' cubes (graphics or compute) or the
//! shadow atlas's faces each frame with their CPU step (placing the lights, planning the
//! atlas), and the debug view of the stores (docs/DESIGN.md#point-light-shadows).

pub mod omni_shadow;
pub mod omni_shadow_compute;
pub mod omni_shadow_pass;
pub mod ray_geometry;
pub mod shadow_atlas;
pub mod shadow_map_view;
pub mod shadow_raster;
pub mod shadow_settings;
pub mod stores;
pub mod sun_map;
pub mod sun_shadow;

use crate::debug_view::{DebugView, Drawn, Legend, ShownStore, ViewNeed, ViewSpec};
use ml_cpu::shading_model::ShadingModel;

/// The `--omni-shadow` modes that draw cubes (the others: the atlas, the rays).
const CUBE_MODES: &[&str] = &["copy", "direct", "multiview", "layered", "compute"];

/// The sun's shadow map over the whole image (blinn-phong, whose sun casts shadows).
pub const SUN_MAP_VIEW: DebugView = DebugView {
    spec: &ViewSpec::plain(
        "shadow-map",
        ml_shaders::debug_view::SHADOW_MAP,
        &[ViewNeed::Shading { model: ShadingModel::BlinnPhong, what: "the blinn-phong model's sun" }, ViewNeed::SunMap],
        Drawn::Store(ShownStore::SunMap),
    ),
};

/// The six faces of the first shadowed point light's cube, unfolded as a cross.
pub const CUBE_VIEW: DebugView = DebugView {
    spec: &ViewSpec::plain(
        "shadow-cube",
        ml_shaders::debug_view::SHADOW_CUBE,
        &[ViewNeed::OmniShadow { what: "point-light shadow cubes", modes: CUBE_MODES }],
        Drawn::Store(ShownStore::Cube),
    ),
};

/// The shadow atlas, every block of it, fitted to the image.
pub const ATLAS_VIEW: DebugView = DebugView {
    spec: &ViewSpec::plain(
        "shadow-atlas",
        ml_shaders::debug_view::SHADOW_ATLAS,
        &[ViewNeed::OmniShadow { what: "the shadow atlas", modes: &["atlas"] }],
        Drawn::Store(ShownStore::Atlas),
    ),
};

/// The traversal steps (nodes visited, triangles tested) of each point's shadow rays as a
/// heat map on a log scale.
pub const RAY_COST_VIEW: DebugView = DebugView {
    spec: &ViewSpec {
        name: "ray-cost",
        code: ml_shaders::debug_view::RAY_COST,
        needs: &[ViewNeed::OmniShadow { what: "shadow rays", modes: &["rays"] }],
        drawn: Drawn::InShading { toned: false, layers: false },
        legend: Legend::Text(
            "log scale: black 0, blue 1, cyan, green, yellow, red 1024 traversal steps (nodes and triangles) of a point's shadow rays",
        ),
    },
};

pub(crate) const VIEWS: &[DebugView] = &[SUN_MAP_VIEW, CUBE_VIEW, ATLAS_VIEW, RAY_COST_VIEW];

#[cfg(test)]
mod tests {
    use super::shadow_settings::OmniShadowMode;

    /// The cube views' modes are the modes that draw cubes, by their names.
    #[test]
    fn cube_modes_are_the_modes_without_atlas_or_rays() {
        let cubes: Vec<&str> = OmniShadowMode::ALL
            .into_iter()
            .filter(|m| !matches!(m, OmniShadowMode::Atlas(_) | OmniShadowMode::Rays))
            .map(OmniShadowMode::name)
            .collect();
        assert_eq!(cubes, super::CUBE_MODES);
    }
}
