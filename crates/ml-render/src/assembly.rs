//! The passes a frame is made of, one file each, and `assemble`, which turns a technique's
//! choices into the ordered list the renderer records. Adding a pass without CPU work of its
//! own adds a file here and a line in `assemble`; one with a per-frame CPU step (the shadow
//! atlas's plan, the exposure meter's EV) also touches the renderer (docs/architecture.md has
//! the checklist).

use crate::clusters::{cluster_assign_cpu, cluster_build};
use crate::exposure::{exposure_meter, tone_map};
use crate::pass::Pass;
use crate::scene::shadow_raster::ShadowViews;
use crate::scene::SceneGpu;
use crate::settings::{
    DebugView, Geometry, LightAssignment, LightingStage, OmniShadowMode, OmniShadowSettings, Raster, RenderSettings, Shading, ShadingModel,
};
use crate::shading::{compute_lighting, deferred_subpass, forward, gbuffer};
use crate::shadows::{omni_shadow_compute, omni_shadow_pass, shadow_map_view};
use crate::visibility::meshlet_cull::Phase;
use crate::visibility::meshlet_scene::MeshletScene;
use crate::visibility::{depth_pyramid, meshlet_cull, triangle_raster_large, visibility_lighting, visibility_raster};
use ml_cpu::gpu_types::PointLight;
use ml_cpu::scene::Scene;
use ml_vk::{vk, Context, VkError};

/// What the passes of a technique are made for.
pub struct Assembly<'a> {
    pub settings: &'a RenderSettings,
    pub shading: Shading,
    /// The scene's lights at rest (the GPU build animates them).
    pub lights: &'a [PointLight],
    pub scene: &'a SceneGpu,
    /// The scene as loaded (the meshlet techniques build their geometry from it).
    pub source: &'a Scene,
    /// Depth format of the technique's raster pass.
    pub depth_format: vk::Format,
}

/// The technique's passes in recording order: point-light shadows, light assignment, the
/// raster pass, lighting after it, then debug views over the result.
pub fn assemble(ctx: &Context, a: &Assembly) -> Result<Vec<Box<dyn Pass>>, VkError> {
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

fn add_passes(ctx: &Context, a: &Assembly, passes: &mut Vec<Box<dyn Pass>>) -> Result<(), VkError> {
    let s = a.settings;
    let technique = s.technique;
    let clustered = technique.assignment() != LightAssignment::None;
    let raster = (a.depth_format, a.shading);
    match s.omni {
        Some(omni @ OmniShadowSettings { mode: OmniShadowMode::Compute { large_list }, .. }) => {
            let views = ShadowViews::Cubes { lights: omni.lights };
            passes.push(Box::new(omni_shadow_compute::OmniShadowCompute::new(ctx, a.scene.meshlets()?, (views, omni.size, large_list))?));
        }
        Some(omni @ OmniShadowSettings { mode: OmniShadowMode::Atlas(_), .. }) => {
            let atlas = &a.scene.omni.atlas;
            let views =
                ShadowViews::Atlas { lights: omni.lights, pairs: atlas.lists.pairs, depths: atlas.depths.raw, tiles: atlas.tiles.raw };
            passes.push(Box::new(omni_shadow_compute::OmniShadowCompute::new(ctx, a.scene.meshlets()?, (views, 0, atlas.lists.large))?));
        }
        Some(_) => passes.push(Box::new(omni_shadow_pass::OmniShadowPass)),
        None => {}
    }
    match technique.assignment() {
        LightAssignment::None => {}
        LightAssignment::Cpu => passes.push(Box::<cluster_assign_cpu::CpuClusterAssign>::default()),
        LightAssignment::Gpu => passes.push(Box::new(cluster_build::ClusterBuild::new(ctx, a.lights, s.clusters.count())?)),
    }
    match (technique.geometry(), technique.lighting_stage()) {
        (Geometry::Meshlets, _) => add_meshlet_passes(ctx, a, passes)?,
        (Geometry::Meshes, LightingStage::Forward) => {
            let legend = s.debug_view == DebugView::ClusterHeat;
            passes.push(Box::new(forward::Forward::new(ctx, a.scene, raster, (clustered, legend), technique.name())?));
        }
        (Geometry::Meshes, LightingStage::Subpass) => {
            passes.push(Box::new(deferred_subpass::DeferredSubpasses::new(ctx, a.scene, raster, clustered)?));
            // pbr's curve, not for surface views (their values are shown as they are).
            let surface_view = !matches!(s.debug_view, DebugView::None | DebugView::ClusterHeat);
            passes.push(Box::new(tone_map::ToneMap::new(ctx, s.shading == ShadingModel::Pbr && !surface_view)?));
        }
        (Geometry::Meshes, LightingStage::Compute) => {
            passes.push(Box::new(gbuffer::GBuffer::new(ctx, a.scene, raster)?));
            passes.push(Box::new(compute_lighting::ComputeLighting::new(ctx, a.scene, a.shading)?));
        }
    }
    if matches!(s.debug_view, DebugView::ShadowMap | DebugView::ShadowCube | DebugView::ShadowAtlas) {
        passes.push(Box::new(shadow_map_view::ShadowMapView::new(ctx, a.scene, s.debug_view)?));
    }
    if s.meters_exposure() {
        passes.push(Box::new(exposure_meter::ExposureMeter::new(ctx, s.shading == ShadingModel::Pbr)?));
    }
    Ok(())
}

/// GPU-driven geometry: early culling and raster, the depth pyramid, late culling and
/// raster, then lighting from the visibility buffer. With the compute raster, each phase's
/// culling also rasterises the small triangles, a compute pass (or, hybrid, the hardware)
/// draws the others into the same 64-bit buffer, and the pyramid and the lighting read that
/// buffer where it lies.
fn add_meshlet_passes(ctx: &Context, a: &Assembly, passes: &mut Vec<Box<dyn Pass>>) -> Result<(), VkError> {
    let (culling, raster) = (a.settings.culling, a.settings.raster);
    let scene = MeshletScene::new(ctx, a.scene.meshlets()?, raster.bin_list().unwrap_or(0))?;
    let compute = raster != Raster::Hardware;
    for phase in [Phase::Early, Phase::Late] {
        passes.push(Box::new(meshlet_cull::MeshletCull::new(ctx, scene.clone(), phase, (culling, raster))?));
        if raster.bin_list().is_some() {
            passes.push(Box::new(triangle_raster_large::TriangleRasterLarge::new(ctx, scene.clone(), phase, raster)?));
        } else {
            passes.push(Box::new(visibility_raster::VisibilityRaster::new(ctx, scene.clone(), (phase, compute), a.depth_format)?));
        }
        if phase == Phase::Early {
            passes.push(Box::new(depth_pyramid::DepthPyramid::new(ctx, compute)?));
        }
    }
    passes.push(Box::new(visibility_lighting::VisibilityLighting::new(ctx, a.scene, (scene, compute), a.shading)?));
    Ok(())
}
