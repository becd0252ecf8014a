//! `assemble`: the passes of a frame made from its plan (`plan::plan`, the ordered pass kinds
//! as data) — each kind's pass constructed for the scene and settings. A new pass is a file
//! in its feature's folder, a `PassKind` with its place in `plan`, and its line here
//! (docs/architecture.md has the checklist). `FEATURES` gathers the rest of every feature
//! (`feature::Feature`: debug views, scene part, lighting constants, scene checks) the same
//! way, a line each.

use crate::clusters::cluster_assign_cpu;
use crate::debug_view::DebugView;
use crate::error::{by_name, Named, RenderError, SettingsError};
use crate::exposure::{exposure_meter, tone_map};
use crate::feature::Feature;
use crate::light_grid::light_grid_build::LightGridBuild;
use crate::light_grid::light_grid_mark::LightGridMark;
use crate::light_stats::light_count::LightCount;
use crate::pass::Pass;
use crate::plan::{plan, PassKind};
use crate::scene::SceneGpu;
use crate::scene_part::MakePart;
use crate::settings::{OmniShadowMode, Raster, RenderSettings, Shading};
use crate::shading::{compute_lighting, deferred_subpass, forward, gbuffer, light_constants, material_lobes, surface_constants};
use crate::shadows::shadow_raster::ShadowViews;
use crate::shadows::stores::SharedShadows;
use crate::shadows::sun_shadow::SunShadowPass;
use crate::shadows::{omni_shadow_compute, omni_shadow_pass, shadow_map_view, shadow_settings};
use crate::specialization::Constants;
use crate::technique::Geometry;
use crate::transparency::transparent_build::{RasterBuffers, TransparentBuild};
use crate::transparency::transparent_resolve::TransparentResolve;
use crate::visibility::meshlet_scene::{MeshletScene, SharedMeshletScene};
use crate::visibility::{depth_pyramid, meshlet_cull, triangle_raster_large, visibility_gather, visibility_lighting, visibility_raster};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::scene::Scene;
use ml_vk::{vk, Context};

/// Every feature's hooks (`feature`), a line each: its debug views in the order lists and
/// menus show them, its scene part (made in this order), its lighting constants, its checks
/// of a scene.
const FEATURES: [Feature; 7] = [
    Feature::views(&[DebugView::NONE]),
    crate::environment::FEATURE,
    crate::clusters::FEATURE,
    SHADING,
    SHADOWS,
    crate::visibility::FEATURE,
    Feature::views(crate::transparency::VIEWS),
];

/// The shading models as a feature: their views, the blinn-phong model's other lights, the
/// lights' and materials' constants (the surfaces' own constants are `lighting`'s first
/// group). Built here: the settings are made of its types (`feature`).
const SHADING: Feature = Feature {
    views: crate::shading::VIEWS,
    part: Some(crate::shading::blinn_phong::make_part),
    lighting: |s, scene| Constants::of(&[&light_constants(s.shading, scene)]),
    ..Feature::NONE
};

/// The shadows as a feature: their views, their constants, and no shadow rays without a light
/// to cast them. Their stores are not a part the list makes: the shadow passes share them.
const SHADOWS: Feature = Feature {
    views: crate::shadows::VIEWS,
    lighting: |s, scene| {
        Constants::of(&[&shadow_settings::lighting_constants(s.omni, s.shadow_config().sun, !scene.directional.is_empty())])
    },
    check_scene: |s, scene| s.check_casters(scene.lights.len(), scene.directional.len()),
    ..Feature::NONE
};

/// How the scene's parts beside the shadow stores are made, in the order the frames ask them.
pub fn scene_parts() -> impl Iterator<Item = MakePart> {
    FEATURES.into_iter().filter_map(|f| f.part)
}

impl RenderSettings {
    /// What the lighting pipelines are compiled for, for `scene`: the surfaces' constants,
    /// then each feature's.
    pub fn lighting(&self, scene: &Scene) -> Shading {
        let model = self.shading;
        let lobe_textures = material_lobes(model, scene) && scene.has_lobe_textures();
        let surface = surface_constants(model, !scene.textures.is_empty(), self.specular_aa, lobe_textures);
        let features = FEATURES.map(|f| (f.lighting)(self, scene));
        let lighting = Constants::of(&features.each_ref().map(Constants::as_slice));
        Shading {
            surface: Constants::of(&[&surface]),
            count_rays: self.light_stats && shadow_settings::traces_rays(lighting.as_slice()),
            lighting,
            transparency: self.blends_layers(),
            blended_cores: self.blends_layers() && self.technique.geometry() == Geometry::Meshlets,
            antialiasing: self.antialiasing,
            background: self.background,
        }
    }

    /// Reject what `scene` cannot give, each feature's checks in turn.
    pub fn check_scene(&self, scene: &Scene) -> Result<(), SettingsError> {
        FEATURES.iter().try_for_each(|f| (f.check_scene)(self, scene))
    }
}

impl DebugView {
    /// Every feature's views, `NONE` first.
    pub fn all() -> impl Iterator<Item = DebugView> {
        FEATURES.into_iter().flat_map(|f| f.views.iter().copied())
    }

    pub fn from_name(name: &str) -> Result<DebugView, RenderError> {
        by_name(&DebugView::all().collect::<Vec<_>>(), DebugView::name, Named::DebugView, name)
    }
}

/// What the passes of a technique are made for.
pub struct Assembly<'a> {
    pub settings: &'a RenderSettings,
    pub shading: Shading,
    /// The scene's lights at rest (the GPU build animates them).
    pub lights: &'a [PointLight],
    pub scene: &'a SceneGpu,
    /// The shadow stores (the shadow passes share them).
    pub shadows: &'a SharedShadows,
    /// The scene's objects (what the transparent layers' build makes room for).
    pub objects: &'a [ml_cpu::scene::Object],
    /// Depth format of the technique's raster pass.
    pub depth_format: vk::Format,
}

/// The technique's passes in recording order: point-light shadows, light assignment, the
/// raster pass, lighting after it, then debug views over the result.
pub fn assemble(ctx: &Context, a: &Assembly) -> Result<Vec<Box<dyn Pass>>, RenderError> {
    let mut passes: Vec<Box<dyn Pass>> = Vec::new();
    match add_passes(ctx, a, &mut passes) {
        Ok(()) => Ok(passes),
        Err(e) => {
            for p in &mut passes {
                p.destroy(ctx);
            }
            Err(e)
        }
    }
}

fn add_passes(ctx: &Context, a: &Assembly, passes: &mut Vec<Box<dyn Pass>>) -> Result<(), RenderError> {
    // The visibility passes share the culling's buffers: made with the first that needs them.
    let mut meshlets: Option<SharedMeshletScene> = None;
    for kind in plan(&a.settings.pipeline_key()) {
        passes.push(make_pass(ctx, a, kind, &mut meshlets)?);
    }
    Ok(())
}

/// The meshlet scene's buffers of a frame slot by name, for the transparent layers' build.
fn raster_buffers(scene: SharedMeshletScene) -> RasterBuffers {
    Box::new(move |slot, name| scene.borrow().slot_buffer(slot, name))
}

/// The pass of `kind` for the assembly's scene and settings.
fn make_pass(ctx: &Context, a: &Assembly, kind: PassKind, meshlets: &mut Option<SharedMeshletScene>) -> Result<Box<dyn Pass>, RenderError> {
    let s = a.settings;
    let raster = (a.depth_format, a.shading);
    // The pyramid and the lighting read the 64-bit buffer, or the hardware raster's images.
    let compute = s.raster.fills_buffer(s.antialiasing);
    // The hybrid's hardware half writes that buffer by atomics.
    let atomic = s.raster != Raster::Hardware;
    // Samples per pixel of that buffer.
    let aa = s.antialiasing;
    // The compute raster lists the soft samples of transparent objects' cores for the layers'
    // build, one sample a pixel (with more, a node a sample swamped the pool where whole
    // pixels are soft, and joining a pixel's samples as the list happened to order them made
    // renders differ).
    let listing_candidates = a.shading.blended_cores
        && aa.samples() == 1
        && s.raster.bin_list().is_some()
        && s.transparency.is_some_and(|t| t.candidate_list > 0)
        && a.objects.iter().any(|o| o.extras.has_core());
    let mut shared = || -> Result<SharedMeshletScene, RenderError> {
        if meshlets.is_none() {
            let candidates = if listing_candidates { s.transparency.map_or(0, |t| t.candidate_list) } else { 0 };
            let lists = (s.raster.bin_list().unwrap_or(0), s.raster.lists_grow(), candidates);
            *meshlets = Some(MeshletScene::new(ctx, a.scene.meshlets()?, lists)?);
        }
        Ok(meshlets.clone().expect("made above"))
    };
    let transparency = || s.transparency.expect("planned with transparency");
    Ok(match kind {
        PassKind::SunShadow => {
            let masked = a.objects.iter().any(|o| o.extras.masked());
            Box::new(SunShadowPass::new(ctx, a.shadows.clone(), s.sun_shadow, (masked, a.scene.meshlets().ok()))?)
        }
        PassKind::OmniShadows => Box::new(omni_shadow_pass::OmniShadowPass::new(a.shadows.clone())),
        PassKind::OmniShadowsCompute => {
            let omni = s.omni.expect("planned with point-light shadows");
            let OmniShadowMode::Compute { large_list } = omni.mode else { unreachable!("planned for the compute mode") };
            let views = ShadowViews::Cubes { lights: omni.lights };
            Box::new(omni_shadow_compute::OmniShadowCompute::new(
                ctx,
                (a.scene.meshlets()?, a.shadows.clone()),
                (views, omni.size, large_list),
            )?)
        }
        PassKind::ShadowAtlas => {
            let omni = s.omni.expect("planned with point-light shadows");
            let (views, large) = {
                let atlas = &a.shadows.borrow().omni.atlas;
                let (pairs, depths, tiles) = (atlas.lists.pairs, atlas.depths.raw, atlas.tiles.raw);
                (ShadowViews::Atlas { lights: omni.lights, pairs, depths, tiles }, atlas.lists.large)
            };
            Box::new(omni_shadow_compute::OmniShadowCompute::new(ctx, (a.scene.meshlets()?, a.shadows.clone()), (views, 0, large))?)
        }
        PassKind::ClusterAssignCpu => Box::<cluster_assign_cpu::CpuClusterAssign>::default(),
        PassKind::LightGridBuild { marked } => Box::new(LightGridBuild::new(ctx, a.lights, marked)?),
        PassKind::LightGridMark { depth_buffer, layers } => {
            let layers = layers.then(|| transparency().lobe_textures);
            Box::new(LightGridMark::new(ctx, (depth_buffer, aa), layers)?)
        }
        PassKind::Forward { lights, heat_legend } => {
            Box::new(forward::Forward::new(ctx, a.scene, raster, (lights, heat_legend), s.technique.name())?)
        }
        PassKind::DeferredSubpasses { clustered } => Box::new(deferred_subpass::DeferredSubpasses::new(ctx, a.scene, raster, clustered)?),
        PassKind::ToneMap { curve, display_linear } => {
            Box::new(tone_map::ToneMap::new(ctx, a.scene, (curve, display_linear), a.shading.background)?)
        }
        PassKind::Backdrop => Box::new(crate::background::Backdrop::new(ctx, a.scene.textures.set_layout.raw)?),
        PassKind::GBuffer => Box::new(gbuffer::GBuffer::new(ctx, a.scene, raster)?),
        PassKind::ComputeLighting => Box::new(compute_lighting::ComputeLighting::new(ctx, a.scene, a.shading)?),
        PassKind::MeshletCull(phase) => {
            let layers = (a.shading.transparency, a.shading.cores_constant(), listing_candidates);
            Box::new(meshlet_cull::MeshletCull::new(ctx, shared()?, phase, (s.culling, s.raster, layers, aa))?)
        }
        PassKind::TriangleRasterLarge(phase) => {
            let cores = a.shading.cores_constant();
            let listing = (cores, listing_candidates);
            Box::new(triangle_raster_large::TriangleRasterLarge::new(ctx, shared()?, phase, (s.raster, aa, listing))?)
        }
        PassKind::VisibilityRaster(phase) => {
            let cores = a.shading.cores_constant();
            Box::new(visibility_raster::VisibilityRaster::new(ctx, shared()?, (phase, atomic, aa, cores), a.depth_format)?)
        }
        PassKind::VisibilityGather(phase) => Box::new(visibility_gather::VisibilityGather::new(ctx, phase, aa)?),
        PassKind::DepthPyramid => Box::new(depth_pyramid::DepthPyramid::new(ctx, compute, aa)?),
        PassKind::VisibilityLighting => {
            Box::new(visibility_lighting::VisibilityLighting::new(ctx, a.scene, (shared()?, compute), (a.shading, aa))?)
        }
        PassKind::ShadowMapView(shown) => Box::new(shadow_map_view::ShadowMapView::new(ctx, a.scene, &a.shadows.borrow(), shown)?),
        PassKind::ExposureMeter { curve } => Box::new(exposure_meter::ExposureMeter::new(ctx, curve)?),
        PassKind::TransparentBuild { depth_buffer } => {
            let meshlets = if depth_buffer { Some(raster_buffers(shared()?)) } else { None };
            Box::new(TransparentBuild::new(
                ctx,
                (a.scene, a.objects, meshlets),
                (a.shading, transparency()),
                (depth_buffer, listing_candidates),
            )?)
        }
        PassKind::TransparentResolve { lights, after_compute } => {
            Box::new(TransparentResolve::new(ctx, a.scene, (a.shading, transparency()), (lights, after_compute))?)
        }
        PassKind::LightCount { depth_buffer } => Box::new(LightCount::new(ctx, a.scene, a.shading, (depth_buffer, aa))?),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Names and codes unique, and every view the shaders know declared by one feature.
    #[test]
    fn every_shader_view_is_declared_once() {
        let views: Vec<DebugView> = DebugView::all().collect();
        let mut names: Vec<&str> = views.iter().map(|v| v.name()).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), views.len(), "a name declared twice");
        let mut codes: Vec<u32> = views.iter().map(|v| v.code()).collect();
        codes.sort_unstable();
        let mut shader: Vec<u32> = ml_shaders::debug_view::ALL.iter().map(|&(_, code)| code).collect();
        shader.sort_unstable();
        assert_eq!(codes, shader, "the views declared and the shaders' DEBUG_VIEW_* differ");
        assert_eq!(views[0], DebugView::NONE);
        for view in views {
            assert_eq!(DebugView::from_name(view.name()).ok(), Some(view));
        }
    }
}
