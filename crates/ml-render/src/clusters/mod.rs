//! Light assignment to the cluster grid on the CPU each frame (clustered-cpu,
//! deferred-clustered; docs/DESIGN.md#clustered-light-assignment). The GPU techniques use
//! the light grid (`crate::light_grid`).

pub mod cluster_assign_cpu;

use crate::debug_view::{DebugView, Drawn, Legend, ViewNeed, ViewSpec};
use crate::feature::Feature;
use crate::report::FrameStats;
use crate::technique::Technique;
use ml_cpu::cluster::ClusterGrid;
use ml_cpu::gpu_types::FrameUniforms;

/// Lights per cluster as a heat map, drawn by the clustered forward fragment shader (the light
/// grid's cells near each point where the grid assigns them): through the tone curve, over
/// the opaque surfaces.
pub const HEAT_VIEW: DebugView = DebugView {
    spec: &ViewSpec {
        name: "cluster-heat",
        code: ml_shaders::debug_view::CLUSTER_HEAT,
        needs: &[ViewNeed::Technique { what: "the clustered forward techniques", holds: Technique::draws_cluster_heat }],
        drawn: Drawn::InShading { toned: true, layers: false },
        legend: Legend::Counted(heat_legend),
    },
};

pub(crate) const VIEWS: &[DebugView] = &[HEAT_VIEW];

/// The clusters as a feature (the assembly's list): their view.
pub const FEATURE: Feature = Feature::views(VIEWS);

/// The heat map's scale: its red is the most lights a cluster (or grid cell) listed.
fn heat_legend(stats: &FrameStats) -> String {
    let grid = stats.feature::<crate::LightGridStats>().map(|g| g.heat_top());
    let top = stats.clusters.map(|c| c.max_lights).or(grid).unwrap_or(1).max(1);
    format!("log scale: black 0, blue 1, cyan, green, yellow, red {top} lights tested")
}

/// The frame uniforms of the cluster grid: its dimensions; its slices' log scale and bias
/// with the heat map's top (`heat_top`, the most lights a cluster listed last); the planes and
/// projection scales its frustum is cut by; and the slot's light-index list capacity
/// (`index_capacity`, what the GPU build may write).
pub fn grid_uniforms(grid: &ClusterGrid, (heat_top, index_capacity): (f32, u32), uniforms: &mut FrameUniforms) {
    uniforms.cluster_dims = [grid.dims.x, grid.dims.y, grid.dims.z, 0];
    uniforms.cluster_slices = [grid.log_scale, grid.log_bias, heat_top, 0.0];
    uniforms.cluster_frustum = [grid.near, grid.far, grid.projection.x_axis.x, grid.projection.y_axis.y];
    uniforms.cluster_build = [index_capacity, 0, 0, 0];
}
