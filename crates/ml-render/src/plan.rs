//! Which passes a frame is made of, as plain data: the settings that make pipelines (a
//! `PipelineKey`) → the ordered list of pass kinds the renderer records (`plan`). No Vulkan
//! here, so the unit tests below check every technique's list — the frames
//! docs/architecture.md draws — without a GPU; `assembly` then makes each kind's pass.
//!
//! Settings fall in three groups by what a change to them costs: the pipeline key (new
//! passes, or a new renderer where the scene's GPU resources depend on it), the view (new
//! frame slots: size, exposure value) and the run (nothing: frame count, clock).

use crate::background::Background;
use crate::settings::{
    Antialiasing, DebugView, Exposure, Geometry, LightAssignment, LightingStage, OmniShadowMode, OmniShadowSettings, Raster,
    RenderSettings, ShadingModel, SunShadowMode, Technique,
};
use crate::shadows::shadow_map_view::ShownStore;
use ml_cpu::cluster::ClusterDims;

/// The early or the late phase of the visibility technique's culling and raster.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub enum Phase {
    Early,
    Late,
}

/// A pass of a frame, as data.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub enum PassKind {
    /// The sun's shadow map (blinn-phong), in the first frame after its casters changed.
    SunShadow,
    /// Point-light shadow cubes by a graphics mode (copy, direct, multiview, layered).
    OmniShadows,
    /// Point-light shadow cubes by the compute shadow raster.
    OmniShadowsCompute,
    /// The frame's shadow atlas faces by the compute shadow raster.
    ShadowAtlas,
    /// Light assignment on the CPU, before the frame is recorded (no GPU work).
    ClusterAssignCpu,
    /// Light assignment on the GPU: the light grid's build (`marked`: after the marks, else
    /// of every cell).
    LightGridBuild { marked: bool },
    /// The light grid's marks: the cells the opaque surfaces' points walk (`depth_buffer`:
    /// from the compute raster's buffer, else the depth target), and with `layers` the
    /// transparent layers' nodes'.
    LightGridMark { depth_buffer: bool, layers: bool },
    /// Forward shading, every light or through the technique's light lists (`lights`: who
    /// assigns them), with the heat map's legend.
    Forward { lights: LightAssignment, heat_legend: bool },
    /// The deferred render pass: G-buffer subpass, lighting subpass.
    DeferredSubpasses { clustered: bool },
    /// HDR → colour target after the deferred subpasses (or the anti-aliased forward pass),
    /// with pbr's curve or as it is; `display_linear`: the samples' mean in the display's
    /// linear light, gamma only.
    ToneMap { curve: bool, display_linear: bool },
    /// The environment where the forward pass drew nothing (background.rs).
    Backdrop,
    /// deferred-compute's G-buffer.
    GBuffer,
    /// deferred-compute's lighting of the G-buffer.
    ComputeLighting,
    /// The visibility technique's culling of a phase.
    MeshletCull(Phase),
    /// The compute raster's large triangles of a phase (by bins).
    TriangleRasterLarge(Phase),
    /// A phase's kept triangles drawn by the hardware (all, or the large ones of the hybrid).
    VisibilityRaster(Phase),
    /// The hardware raster's samples (anti-aliasing) gathered into the 64-bit buffer after a
    /// phase's draw.
    VisibilityGather(Phase),
    /// The depth pyramid the late culling tests against.
    DepthPyramid,
    /// Lighting from the visibility buffer.
    VisibilityLighting,
    /// The debug views that paint a shadow store (the sun's map, a cube, the atlas).
    ShadowMapView(ShownStore),
    /// Auto exposure's meter, reading the finished image (with pbr's curve or without).
    ExposureMeter { curve: bool },
    /// The transparent objects' fragments into per-pixel lists, tested against the opaque
    /// depth (`depth_buffer`: the compute raster's buffer, else the depth target).
    TransparentBuild { depth_buffer: bool },
    /// The layers lit and blended over the opaque HDR image, encoded into the colour target;
    /// `after_compute`: a compute lighting pass wrote that image (else a render pass).
    TransparentResolve { lights: LightAssignment, after_compute: bool },
    /// Lights tested and reaching per pixel, counted after the lighting (`depth_buffer`: from
    /// the compute raster's buffer, else the depth target).
    LightCount { depth_buffer: bool },
}

/// What the passes and their pipelines are made for. A change in `technique`, `shading`,
/// `omni`, `sun_shadow`, `raster` or `culling` needs a new renderer (the scene's GPU
/// resources depend on them); in `clusters`, `debug_view` or `meters_exposure` new passes.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Debug)]
pub struct PipelineKey {
    pub technique: Technique,
    pub shading: ShadingModel,
    pub omni: Option<OmniShadowSettings>,
    pub sun_shadow: SunShadowMode,
    pub raster: Raster,
    pub culling: bool,
    pub clusters: ClusterDims,
    pub debug_view: DebugView,
    /// Auto exposure meters the image (auto exposure, no debug view).
    pub meters_exposure: bool,
    /// Transparent objects are blended in per-pixel layers (`RenderSettings::blends_layers`).
    pub layers: bool,
    /// The lights tested and reaching per pixel are counted (`RenderSettings::light_stats`).
    pub light_stats: bool,
    /// The light grid marks the cells near the surfaces first, where the technique knows them
    /// (`RenderSettings::light_grid_marks`).
    pub light_grid_marks: bool,
    /// Coverage samples per pixel (`RenderSettings::antialiasing`).
    pub antialiasing: Antialiasing,
    /// What pixels no surface covers show.
    pub background: Background,
}

impl PipelineKey {
    /// The part of the key the renderer's scene resources are made for: equal parts, the
    /// renderer can change its passes in place.
    pub fn renderer_part(&self) -> (Technique, ShadingModel, Option<OmniShadowSettings>, SunShadowMode, Raster, bool) {
        (self.technique, self.shading, self.omni, self.sun_shadow, self.raster, self.culling)
    }
}

/// What the frame slots are made for: a change makes new slots, not new passes.
#[derive(Clone, Copy, PartialEq, Debug)]
pub struct ViewConfig {
    pub width: u32,
    pub height: u32,
    pub exposure: Exposure,
}

/// What a render runs: changes cost nothing.
#[derive(Clone, Copy, PartialEq, Debug)]
pub struct RunParams {
    pub frames: u32,
    pub time: Option<f32>,
}

impl RenderSettings {
    pub fn pipeline_key(&self) -> PipelineKey {
        PipelineKey {
            technique: self.technique,
            shading: self.shading,
            omni: self.omni,
            sun_shadow: self.sun_shadow,
            raster: self.raster,
            culling: self.culling,
            clusters: self.clusters,
            debug_view: self.debug_view,
            meters_exposure: self.meters_exposure(),
            layers: self.blends_layers(),
            light_stats: self.light_stats,
            light_grid_marks: self.light_grid_marks,
            antialiasing: self.antialiasing,
            background: self.background,
        }
    }

    pub fn view_config(&self) -> ViewConfig {
        ViewConfig { width: self.width, height: self.height, exposure: self.exposure }
    }

    pub fn run_params(&self) -> RunParams {
        RunParams { frames: self.frames, time: self.time }
    }
}

/// The passes of a frame in recording order: the sun's and the point lights' shadows, light
/// assignment, the raster pass and lighting after it, then debug views and the exposure meter
/// over the result.
pub fn plan(key: &PipelineKey) -> Vec<PassKind> {
    let mut kinds = Vec::new();
    let technique = key.technique;
    // Shadow rays toward the sun read no map.
    if key.shading == ShadingModel::BlinnPhong && key.sun_shadow != SunShadowMode::Rays {
        kinds.push(PassKind::SunShadow);
    }
    match key.omni.map(|o| o.mode) {
        Some(OmniShadowMode::Compute { .. }) => kinds.push(PassKind::OmniShadowsCompute),
        Some(OmniShadowMode::Atlas(_)) => kinds.push(PassKind::ShadowAtlas),
        // Shadow rays are traced by the lighting itself.
        Some(OmniShadowMode::Rays) | None => {}
        Some(_) => kinds.push(PassKind::OmniShadows),
    }
    let antialiased = key.antialiasing != Antialiasing::Off;
    // The opaque depth after the raster: the 64-bit buffer (the compute rasters', or the
    // hardware raster's samples gathered into it), or the depth target.
    let opaque_depth_buffer = technique.geometry() == Geometry::Meshlets && key.raster.fills_buffer(key.antialiasing);
    // The light grid is built once the surfaces are known, for the cells their points walk,
    // where a technique knows them before its lighting (the opaque depth, the transparent
    // layers' nodes) and the settings want the marks; else first, for every cell.
    let lights = technique.assignment();
    // The marks read a single-sampled depth target or the 64-bit buffer: with anti-aliasing's
    // multisampled G-buffer, deferred-compute builds the grid for every cell.
    let marks = technique.marks_light_grid() && key.light_grid_marks && !(antialiased && technique.geometry() == Geometry::Meshes);
    let marked_build =
        [PassKind::LightGridMark { depth_buffer: opaque_depth_buffer, layers: key.layers }, PassKind::LightGridBuild { marked: true }];
    let marked_build = if marks { &marked_build[..] } else { &[] };
    match lights {
        LightAssignment::None => {}
        LightAssignment::Cpu => kinds.push(PassKind::ClusterAssignCpu),
        LightAssignment::Gpu if !marks => kinds.push(PassKind::LightGridBuild { marked: false }),
        LightAssignment::Gpu => {}
    }
    let clustered = lights == LightAssignment::Cpu;
    // Transparent layers: built once the opaque depth is known, resolved over the opaque
    // pass's linear HDR output.
    let build = PassKind::TransparentBuild { depth_buffer: opaque_depth_buffer };
    let after_compute = technique.lighting_stage() == LightingStage::Compute;
    let resolve = PassKind::TransparentResolve { lights, after_compute };
    match (technique.geometry(), technique.lighting_stage()) {
        (Geometry::Meshlets, _) => {
            for phase in [Phase::Early, Phase::Late] {
                kinds.push(PassKind::MeshletCull(phase));
                kinds.push(match key.raster {
                    Raster::Compute { .. } if key.raster.bin_list().is_some() => PassKind::TriangleRasterLarge(phase),
                    _ => PassKind::VisibilityRaster(phase),
                });
                if key.raster == Raster::Hardware && antialiased {
                    kinds.push(PassKind::VisibilityGather(phase));
                }
                if phase == Phase::Early {
                    kinds.push(PassKind::DepthPyramid);
                }
            }
            kinds.extend(key.layers.then_some(build));
            kinds.extend(marked_build);
            kinds.push(PassKind::VisibilityLighting);
            kinds.extend(key.layers.then_some(resolve));
        }
        (Geometry::Meshes, LightingStage::Forward) => {
            kinds.push(PassKind::Forward { lights, heat_legend: key.debug_view == crate::clusters::HEAT_VIEW });
            if key.layers {
                kinds.extend([build, resolve]);
            } else if antialiased {
                kinds.push(PassKind::ToneMap { curve: false, display_linear: true });
            } else if key.background == Background::Environment {
                // The pass wrote the output itself: the backdrop where it drew nothing.
                kinds.push(PassKind::Backdrop);
            }
        }
        (Geometry::Meshes, LightingStage::Subpass) => {
            kinds.push(PassKind::DeferredSubpasses { clustered });
            if key.layers {
                kinds.extend([build, resolve]);
            } else {
                // pbr's curve, not for surface views (their values are shown as they are).
                let curve = key.shading == ShadingModel::Pbr && key.debug_view.toned() && !antialiased;
                kinds.push(PassKind::ToneMap { curve, display_linear: antialiased });
            }
        }
        (Geometry::Meshes, LightingStage::Compute) => {
            kinds.push(PassKind::GBuffer);
            kinds.extend(key.layers.then_some(build));
            kinds.extend(marked_build);
            kinds.push(PassKind::ComputeLighting);
            kinds.extend(key.layers.then_some(resolve));
        }
    }
    if key.light_stats {
        kinds.push(PassKind::LightCount { depth_buffer: opaque_depth_buffer });
    }
    kinds.extend(key.debug_view.shown_store().map(PassKind::ShadowMapView));
    if key.meters_exposure {
        kinds.push(PassKind::ExposureMeter { curve: key.shading == ShadingModel::Pbr });
    }
    kinds
}

#[cfg(test)]
mod tests {
    use super::PassKind::*;
    use super::*;
    use crate::settings::{AtlasSettings, LargeTriangles};

    /// The key of `technique` with the binary's defaults: pbr, auto exposure.
    fn key(technique: Technique) -> PipelineKey {
        RenderSettings { shading: ShadingModel::Pbr, exposure: Exposure::Auto, ..RenderSettings::new(technique, 64, 64) }.pipeline_key()
    }

    fn shadowed(mut k: PipelineKey, mode: OmniShadowMode) -> PipelineKey {
        k.omni = Some(OmniShadowSettings { mode, lights: 4, all: false, size: 64 });
        k
    }

    #[test]
    fn each_technique_gets_the_frame_the_architecture_draws() {
        let cases: [(Technique, &[PassKind]); 6] = [
            (Technique::Forward, &[Forward { lights: LightAssignment::None, heat_legend: false }]),
            (Technique::ClusteredCpu, &[ClusterAssignCpu, Forward { lights: LightAssignment::Cpu, heat_legend: false }]),
            (Technique::ClusteredGpu, &[LightGridBuild { marked: false }, Forward { lights: LightAssignment::Gpu, heat_legend: false }]),
            (Technique::Deferred, &[DeferredSubpasses { clustered: false }, ToneMap { curve: true, display_linear: false }]),
            (
                Technique::DeferredClustered,
                &[ClusterAssignCpu, DeferredSubpasses { clustered: true }, ToneMap { curve: true, display_linear: false }],
            ),
            (
                Technique::DeferredCompute,
                &[GBuffer, LightGridMark { depth_buffer: false, layers: false }, LightGridBuild { marked: true }, ComputeLighting],
            ),
        ];
        for (technique, expected) in cases {
            let mut k = key(technique);
            k.meters_exposure = false;
            assert_eq!(plan(&k), expected, "{}", technique.name());
        }
    }

    #[test]
    fn visibility_culls_and_draws_in_two_phases_around_the_pyramid() {
        let mut k = key(Technique::Visibility);
        k.meters_exposure = false;
        // The light grid after the raster, for the cells the surfaces' points walk.
        let phases = |raster: fn(Phase) -> PassKind, depth_buffer| {
            vec![
                MeshletCull(Phase::Early),
                raster(Phase::Early),
                DepthPyramid,
                MeshletCull(Phase::Late),
                raster(Phase::Late),
                LightGridMark { depth_buffer, layers: false },
                LightGridBuild { marked: true },
                VisibilityLighting,
            ]
        };
        k.raster = Raster::Hardware;
        assert_eq!(plan(&k), phases(VisibilityRaster, false));
        k.raster = Raster::hybrid(64);
        assert_eq!(plan(&k), phases(VisibilityRaster, true), "hybrid: large triangles by the hardware");
        k.raster = Raster::compute(64);
        assert!(matches!(k.raster, Raster::Compute { large: LargeTriangles::Bins { .. }, .. }));
        assert_eq!(plan(&k), phases(TriangleRasterLarge, true));
    }

    #[test]
    fn without_marks_the_light_grid_is_built_first_for_every_cell() {
        for technique in [Technique::DeferredCompute, Technique::Visibility] {
            let mut k = key(technique);
            k.light_grid_marks = false;
            let kinds = plan(&k);
            assert!(kinds.contains(&LightGridBuild { marked: false }), "{}: {kinds:?}", technique.name());
            assert!(!kinds.iter().any(|p| matches!(p, LightGridMark { .. } | LightGridBuild { marked: true })), "{kinds:?}");
        }
        // Techniques without surfaces before their lighting never mark.
        assert!(!Technique::ClusteredGpu.marks_light_grid());
    }

    #[test]
    fn shadows_come_first_and_views_and_the_meter_last() {
        let forward = Forward { lights: LightAssignment::None, heat_legend: false };
        let k = key(Technique::Forward);
        assert!(k.meters_exposure, "auto exposure is the default");
        assert_eq!(plan(&k), [forward, ExposureMeter { curve: true }]);
        for (mode, first) in [
            (OmniShadowMode::Layered, OmniShadows),
            (OmniShadowMode::COMPUTE, OmniShadowsCompute),
            (OmniShadowMode::Atlas(AtlasSettings::DEFAULT), ShadowAtlas),
        ] {
            let mut k = shadowed(key(Technique::Forward), mode);
            k.debug_view = crate::shadows::CUBE_VIEW;
            k.meters_exposure = false;
            assert_eq!(plan(&k), [first, forward, ShadowMapView(ShownStore::Cube)], "{}", mode.name());
        }
        // Shadow rays are traced in the lighting: no pass of their own.
        let mut k = shadowed(key(Technique::Forward), OmniShadowMode::Rays);
        k.meters_exposure = false;
        assert_eq!(plan(&k), [forward]);
        // The sun's map (blinn-phong) before the point lights' shadows; none for its rays.
        k.shading = ShadingModel::BlinnPhong;
        let k = shadowed(k, OmniShadowMode::Layered);
        assert_eq!(plan(&k), [SunShadow, OmniShadows, forward]);
        assert_eq!(plan(&PipelineKey { sun_shadow: SunShadowMode::Rays, ..k }), [OmniShadows, forward]);
        let mut k = key(Technique::ClusteredGpu);
        k.debug_view = crate::clusters::HEAT_VIEW;
        k.meters_exposure = false;
        assert_eq!(plan(&k), [LightGridBuild { marked: false }, Forward { lights: LightAssignment::Gpu, heat_legend: true }]);
    }

    #[test]
    fn transparent_layers_are_built_after_the_opaque_depth_and_resolved_over_its_light() {
        let build = TransparentBuild { depth_buffer: false };
        let resolve = |lights, after_compute| TransparentResolve { lights, after_compute };
        let cases: [(Technique, &[PassKind]); 4] = [
            (
                Technique::Forward,
                &[Forward { lights: LightAssignment::None, heat_legend: false }, build, resolve(LightAssignment::None, false)],
            ),
            (
                Technique::ClusteredGpu,
                &[
                    LightGridBuild { marked: false },
                    Forward { lights: LightAssignment::Gpu, heat_legend: false },
                    build,
                    resolve(LightAssignment::Gpu, false),
                ],
            ),
            (
                Technique::DeferredClustered,
                &[ClusterAssignCpu, DeferredSubpasses { clustered: true }, build, resolve(LightAssignment::Cpu, false)],
            ),
            (
                Technique::DeferredCompute,
                &[
                    GBuffer,
                    build,
                    LightGridMark { depth_buffer: false, layers: true },
                    LightGridBuild { marked: true },
                    ComputeLighting,
                    resolve(LightAssignment::Gpu, true),
                ],
            ),
        ];
        for (technique, expected) in cases {
            let mut k = key(technique);
            k.layers = true;
            k.meters_exposure = false;
            assert_eq!(plan(&k), expected, "{}", technique.name());
        }
        let mut k = key(Technique::Visibility);
        (k.layers, k.meters_exposure, k.raster) = (true, false, Raster::compute(64));
        assert_eq!(
            plan(&k)[5..],
            [
                TransparentBuild { depth_buffer: true },
                LightGridMark { depth_buffer: true, layers: true },
                LightGridBuild { marked: true },
                VisibilityLighting,
                resolve(LightAssignment::Gpu, true)
            ],
            "the grid marked from the opaque depth and the layers' nodes"
        );
        // A surface view shows the opaque surfaces only; the layers' own view keeps them.
        let mut s = RenderSettings { transparency: Some(Default::default()), ..RenderSettings::new(Technique::Forward, 64, 64) };
        s.debug_view = DebugView::from_name("gbuffer-albedo").unwrap();
        assert!(!s.pipeline_key().layers);
        s.debug_view = crate::transparency::LAYERS_VIEW;
        assert!(s.pipeline_key().layers);
    }

    #[test]
    fn the_light_counts_follow_the_lighting_and_precede_the_meter() {
        let mut k = key(Technique::DeferredCompute);
        k.light_stats = true;
        assert_eq!(
            plan(&k),
            [
                GBuffer,
                LightGridMark { depth_buffer: false, layers: false },
                LightGridBuild { marked: true },
                ComputeLighting,
                LightCount { depth_buffer: false },
                ExposureMeter { curve: true }
            ]
        );
        let mut k = key(Technique::Visibility);
        (k.light_stats, k.meters_exposure, k.raster) = (true, false, Raster::compute(64));
        assert_eq!(plan(&k)[7..], [VisibilityLighting, LightCount { depth_buffer: true }]);
        let s = RenderSettings { light_stats: true, ..RenderSettings::new(Technique::Visibility, 64, 64) };
        assert!(s.pipeline_key().light_stats);
    }

    #[test]
    fn surface_views_skip_the_tone_curve_and_blinn_phong_has_none() {
        let mut k = key(Technique::Deferred);
        k.meters_exposure = false;
        k.debug_view = DebugView::from_name("gbuffer-normal").unwrap();
        assert_eq!(plan(&k)[1], ToneMap { curve: false, display_linear: false });
        k.debug_view = DebugView::NONE;
        k.shading = ShadingModel::BlinnPhong;
        assert_eq!(plan(&k)[2], ToneMap { curve: false, display_linear: false });
    }

    #[test]
    fn a_multisampled_gbuffer_builds_the_light_grid_for_every_cell() {
        let mut k = key(Technique::DeferredCompute);
        (k.meters_exposure, k.antialiasing) = (false, Antialiasing::X4);
        assert_eq!(plan(&k), [LightGridBuild { marked: false }, GBuffer, ComputeLighting]);
    }

    #[test]
    fn multisampled_meshes_are_resolved_in_the_display_light_and_gamma_encoded() {
        let gamma_only = ToneMap { curve: false, display_linear: true };
        for technique in [Technique::Forward, Technique::ClusteredGpu, Technique::Deferred, Technique::DeferredClustered] {
            let mut k = key(technique);
            (k.meters_exposure, k.antialiasing) = (false, Antialiasing::X4);
            assert_eq!(plan(&k).last(), Some(&gamma_only), "{}", technique.name());
        }
    }

    #[test]
    fn the_environment_background_follows_a_forward_pass_that_writes_the_output_itself() {
        for technique in [Technique::Forward, Technique::ClusteredCpu, Technique::ClusteredGpu] {
            let mut k = key(technique);
            (k.meters_exposure, k.background) = (false, Background::Environment);
            assert_eq!(plan(&k).last(), Some(&Backdrop), "{}", technique.name());
            // With samples the tone map lays it; with the colour nothing needs to.
            k.antialiasing = Antialiasing::X4;
            assert!(!plan(&k).contains(&Backdrop));
            (k.antialiasing, k.background) = (Antialiasing::Off, Background::Colour);
            assert!(!plan(&k).contains(&Backdrop));
        }
        // The other techniques' last pass writes every pixel and lays it there.
        for technique in [Technique::Deferred, Technique::DeferredCompute, Technique::Visibility] {
            let mut k = key(technique);
            k.background = Background::Environment;
            assert!(!plan(&k).contains(&Backdrop), "{}", technique.name());
        }
    }

    #[test]
    fn the_key_leaves_out_what_does_not_make_pipelines() {
        let a = RenderSettings::new(Technique::Visibility, 64, 64);
        let b = RenderSettings { width: 128, height: 32, frames: 9, time: Some(1.0), exposure: Exposure::Ev(2.0), ..a };
        assert_eq!(a.pipeline_key(), b.pipeline_key());
        assert_ne!(a.view_config(), b.view_config());
        assert_ne!(a.run_params(), b.run_params());
        let auto = RenderSettings { exposure: Exposure::Auto, ..a };
        assert_ne!(a.pipeline_key(), auto.pipeline_key(), "auto exposure adds the meter");
        // Hashable: a cache of pipelines may be keyed by it.
        let set: std::collections::HashSet<PipelineKey> = [a.pipeline_key(), b.pipeline_key()].into();
        assert_eq!(set.len(), 1);
    }
}
