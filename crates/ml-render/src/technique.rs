//! The vocabulary of the choices a render starts from: the technique (where lights are
//! assigned, where the lighting runs, how geometry reaches the pixels) and who draws the
//! visibility buffer. A leaf module: the settings, the targets and the passes all read it.

use crate::antialiasing::Antialiasing;
use crate::error::{by_name, Named, RenderError};

/// Lighting techniques (docs/DESIGN.md#techniques-are-two-choices). Each must give the same image as `Forward`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Technique {
    /// Brute force: every fragment loops over every light.
    Forward,
    /// Cluster grid with lights assigned on the CPU every frame.
    ClusteredCpu,
    /// The light grid (world-space cells of the lights' size) built by compute shaders every
    /// frame, lights moved on the GPU; every fragment walks the cells near it.
    ClusteredGpu,
    /// One render pass, G-buffer subpass → lighting subpass (input attachments),
    /// every light per pixel, into an HDR target; then a tone-map pass.
    Deferred,
    /// `Deferred` with the lighting subpass looping over its cluster's lights (CPU-assigned).
    DeferredClustered,
    /// clustered-gpu's light grid, with the lighting as a compute pass over a G-buffer.
    DeferredCompute,
    /// GPU-driven: meshlets culled on the GPU (frustum, back-face cones, occlusion in two
    /// phases), drawn indirectly into a visibility buffer, lit by a compute pass through
    /// clustered-gpu's light grid.
    Visibility,
}

impl Technique {
    pub const ALL: [Technique; 7] = [
        Technique::Forward,
        Technique::ClusteredCpu,
        Technique::ClusteredGpu,
        Technique::Deferred,
        Technique::DeferredClustered,
        Technique::DeferredCompute,
        Technique::Visibility,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Technique::Forward => "forward",
            Technique::ClusteredCpu => "clustered-cpu",
            Technique::ClusteredGpu => "clustered-gpu",
            Technique::Deferred => "deferred",
            Technique::DeferredClustered => "deferred-clustered",
            Technique::DeferredCompute => "deferred-compute",
            Technique::Visibility => "visibility",
        }
    }

    /// Where lights are assigned to clusters (docs/DESIGN.md#techniques-are-two-choices).
    pub fn assignment(self) -> LightAssignment {
        match self {
            Technique::Forward | Technique::Deferred => LightAssignment::None,
            Technique::ClusteredCpu | Technique::DeferredClustered => LightAssignment::Cpu,
            Technique::ClusteredGpu | Technique::DeferredCompute | Technique::Visibility => LightAssignment::Gpu,
        }
    }

    /// Where the lighting runs.
    pub fn lighting_stage(self) -> LightingStage {
        match self {
            Technique::Forward | Technique::ClusteredCpu | Technique::ClusteredGpu => LightingStage::Forward,
            Technique::Deferred | Technique::DeferredClustered => LightingStage::Subpass,
            Technique::DeferredCompute | Technique::Visibility => LightingStage::Compute,
        }
    }

    /// How the geometry reaches the pixels.
    pub fn geometry(self) -> Geometry {
        match self {
            Technique::Visibility => Geometry::Meshlets,
            _ => Geometry::Meshes,
        }
    }

    /// Whether lights are assigned to lists (cluster lists or the light grid), not all looped.
    pub fn is_clustered(self) -> bool {
        self.assignment() != LightAssignment::None
    }

    /// Whether its light grid may mark the cells near the surfaces before its build: the GPU
    /// assignment of a technique that knows its surfaces before its lighting (its visibility
    /// buffer or G-buffer; deferred-compute, visibility).
    pub fn marks_light_grid(self) -> bool {
        self.assignment() == LightAssignment::Gpu
            && (self.geometry() == Geometry::Meshlets || self.lighting_stage() == LightingStage::Compute)
    }

    /// Whether it has the cluster grid (`--clusters`): the techniques that assign on the CPU.
    pub fn has_cluster_grid(self) -> bool {
        self.assignment() == LightAssignment::Cpu
    }

    /// Whether it draws meshlets, culled on the GPU, into a visibility buffer.
    pub fn draws_meshlets(self) -> bool {
        self.geometry() == Geometry::Meshlets
    }

    /// Whether it draws the cluster-heat debug view: the clustered forward fragment shader
    /// does.
    pub fn draws_cluster_heat(self) -> bool {
        self.is_clustered() && self.lighting_stage() == LightingStage::Forward
    }

    /// Whether the lighting runs in the second subpass of the raster pass.
    pub fn lights_in_subpass(self) -> bool {
        self.lighting_stage() == LightingStage::Subpass
    }

    /// Whether the lighting runs as a compute pass over a G-buffer.
    pub fn lights_in_compute(self) -> bool {
        self.lighting_stage() == LightingStage::Compute
    }

    pub fn from_name(name: &str) -> Result<Technique, RenderError> {
        by_name(&Technique::ALL, Technique::name, Named::Technique, name)
    }
}

/// Where lights are assigned to lists, and so which lists the light loop walks.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LightAssignment {
    /// Nowhere: every pixel loops over every light.
    None,
    /// To the cluster grid on the CPU every frame, uploaded into the frame's lists.
    Cpu,
    /// To the light grid by compute shaders every frame (which also move the lights).
    Gpu,
}

/// Where the lighting runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightingStage {
    /// In the fragment shader that draws the objects.
    Forward,
    /// In the second subpass of the deferred render pass, over the G-buffer.
    Subpass,
    /// In a compute pass over the G-buffer.
    Compute,
}

/// How the geometry reaches the pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// Every object's mesh drawn with one draw call from the CPU, every frame.
    Meshes,
    /// Meshlets culled on the GPU and drawn by indirect draws into a visibility buffer.
    Meshlets,
}

/// Who draws the visibility buffer (technique visibility; docs/DESIGN.md#compute-raster).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Raster {
    /// The graphics pipeline: each culling phase's triangles in one indexed draw.
    Hardware,
    /// A compute shader for every triangle whose bounding box is at most `split` pixels a side
    /// and which lies wholly beyond the near plane; the others — large ones, and those
    /// crossing the near plane — drawn into the same 64-bit buffer as `large` says.
    Compute { split: u32, large: LargeTriangles },
}

/// Who draws the compute raster's large triangles.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LargeTriangles {
    /// The hardware, in each phase's indexed draw (`--raster hybrid`).
    Hardware,
    /// Compute too (`--raster compute`): clipped once, and drawn by a work group per
    /// 64×64-pixel bin of their box. `bin_list`: large triangles, and bins, the lists hold per
    /// culling phase at first; past them the thread that found a triangle draws it alone
    /// (slow; and a CPU driver may cut a long loop short). `grows`: a frame slot's lists grow
    /// after a frame that overflowed them, and a render's last frame is drawn again with
    /// them grown (false: fixed lists, which tests of drawing in place ask for).
    Bins { bin_list: u32, grows: bool },
}

impl Raster {
    /// The compute raster's default split: triangles up to this many pixels a side are drawn
    /// in compute (measured: docs/BENCHMARKS.md).
    pub const DEFAULT_SPLIT: u32 = 16;
    /// Its largest: the edge functions of a 64-pixel box at 1/256 pixel stay in 32 bits.
    pub const MAX_SPLIT: u32 = 64;
    /// The lists' default size: 2^16 large triangles and bins (7.5 MiB per frame in flight),
    /// the bins of 32 screens of 3840×2160.
    pub const DEFAULT_BIN_LIST: u32 = 1 << 16;

    /// The compute raster (large triangles too) with `split`.
    pub fn compute(split: u32) -> Raster {
        Raster::Compute { split, large: LargeTriangles::Bins { bin_list: Raster::DEFAULT_BIN_LIST, grows: true } }
    }

    /// The hybrid raster (large triangles by the hardware) with `split`.
    pub fn hybrid(split: u32) -> Raster {
        Raster::Compute { split, large: LargeTriangles::Hardware }
    }

    pub fn name(self) -> &'static str {
        match self {
            Raster::Hardware => "hardware",
            Raster::Compute { large: LargeTriangles::Hardware, .. } => "hybrid",
            Raster::Compute { large: LargeTriangles::Bins { .. }, .. } => "compute",
        }
    }

    /// The rasteriser `name` names (`hardware`, `hybrid`, `compute`), those in compute with
    /// `split`.
    pub fn from_name(name: &str, split: u32) -> Result<Raster, RenderError> {
        by_name(&[Raster::Hardware, Raster::hybrid(split), Raster::compute(split)], Raster::name, Named::Raster, name)
    }

    /// The largest triangle drawn in compute by one thread (0: none).
    pub fn split(self) -> u32 {
        match self {
            Raster::Hardware => 0,
            Raster::Compute { split, .. } => split,
        }
    }

    /// Whether the visibility technique's passes after this raster (the depth pyramid, the
    /// light grid's marks, the lighting) read the 64-bit depth-and-id buffer rather than the
    /// hardware raster's images: the rasters in compute draw into it, and with anti-aliasing
    /// the hardware raster's samples are gathered into it.
    pub fn fills_buffer(self, antialiasing: Antialiasing) -> bool {
        self != Raster::Hardware || antialiasing != Antialiasing::Off
    }

    /// The large triangles' bin list's size, where they are drawn in compute.
    pub fn bin_list(self) -> Option<u32> {
        match self {
            Raster::Compute { large: LargeTriangles::Bins { bin_list, .. }, .. } => Some(bin_list),
            _ => None,
        }
    }

    /// Whether the large triangles' lists grow when a frame overflows them.
    pub fn lists_grow(self) -> bool {
        matches!(self, Raster::Compute { large: LargeTriangles::Bins { grows: true, .. }, .. })
    }
}

/// The first device feature `raster` needs that `features` lacks, if any.
pub fn missing_raster_feature(raster: Raster, features: &ml_vk::OptionalFeatures) -> Option<&'static str> {
    let Raster::Compute { large, .. } = raster else {
        return None;
    };
    let atomics = (features.buffer_int64_atomics, "shaderInt64 and shaderBufferInt64Atomics (64-bit integers and atomic min on buffers)");
    let fragment = (
        features.fragment_stores_and_atomics || large != LargeTriangles::Hardware,
        "fragmentStoresAndAtomics (the large triangles' fragments write the same buffer)",
    );
    let ballot = (features.compute_subgroup_ballot, "subgroup ballot in compute shaders (the masked raster gathers covered pixels)");
    [atomics, fragment, ballot].into_iter().find_map(|(has, feature)| (!has).then_some(feature))
}

/// The first device feature the meshlet techniques need that `features` lacks, if any.
pub fn missing_meshlet_feature(features: &ml_vk::OptionalFeatures) -> Option<&'static str> {
    [
        (features.full_draw_index_uint32, "fullDrawIndexUint32 (32-bit index values)"),
        (features.geometry_shader, "geometryShader (gl_PrimitiveID in fragment shaders)"),
    ]
    .into_iter()
    .find_map(|(has, feature)| (!has).then_some(feature))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_compute_rasters_name_the_first_feature_a_device_lacks() {
        let all = ml_vk::OptionalFeatures {
            buffer_int64_atomics: true,
            fragment_stores_and_atomics: true,
            compute_subgroup_ballot: true,
            ..ml_vk::OptionalFeatures::default()
        };
        assert_eq!(missing_raster_feature(Raster::compute(16), &all), None);
        let no_ballot = ml_vk::OptionalFeatures { compute_subgroup_ballot: false, ..all };
        let missing = missing_raster_feature(Raster::compute(16), &no_ballot).expect("the ballot is needed");
        assert!(missing.contains("subgroup ballot"), "{missing}");
        let none = ml_vk::OptionalFeatures::default();
        assert!(missing_raster_feature(Raster::compute(16), &none).is_some_and(|m| m.contains("shaderInt64")));
        // The hardware raster needs none of them.
        assert_eq!(missing_raster_feature(Raster::Hardware, &none), None);
    }
}
