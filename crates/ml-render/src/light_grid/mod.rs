//! The light grid (docs/DESIGN.md#the-light-grid): the light assignment of the GPU techniques
//! (clustered-gpu, deferred-compute, visibility). Lights are listed per cell of a world-space
//! grid with cells about the lights' radius, rebuilt by compute shaders every frame from the
//! moved lights (`light_grid_build`); a surface point walks the rows of cells within reach of
//! it (shaders/light_grid/light_grid.glsl). What a pixel tests then follows the lights near
//! it, not the lights in the scene; the cells' shape is `ml_cpu::light_grid`'s.

pub mod light_grid_build;
pub mod light_grid_mark;

use crate::report::FeatureStats;

/// What the last frame's build listed.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LightGridStats {
    /// Cells per axis and their edge (m).
    pub dims: [u32; 3],
    pub cell: f32,
    /// Cells marked (within reach of a surface point of the frame; all where the technique
    /// has no surfaces before its lighting).
    pub cells_marked: u32,
    /// Lights in the scene; of them listed (wide, or in a marked cell), of those wide
    /// (tested by every point).
    pub lights: u32,
    pub listed: u32,
    pub wide: u32,
    /// Most lights in one cell.
    pub max_per_cell: u32,
}

impl LightGridStats {
    /// The most lights a point may test, about: the wide lights and its 27 nearest cells at
    /// their fullest (the cluster-heat view's top).
    pub fn heat_top(&self) -> u32 {
        self.wide + 27 * self.max_per_cell
    }
}

impl FeatureStats for LightGridStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let [x, y, z] = self.dims;
        vec![(
            "light grid",
            format!(
                "{x}x{y}x{z} cells of {:.3} m, {} marked; {} of {} lights listed, {} wide; at most {} in a cell",
                self.cell, self.cells_marked, self.listed, self.lights, self.wide, self.max_per_cell
            ),
        )]
    }
}
