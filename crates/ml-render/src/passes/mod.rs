//! The passes a frame is made of, one file each, and `assemble`, which turns a technique's
//! choices into the ordered list the renderer records. Adding a pass adds a file here and a
//! line in `assemble`; the renderer does not change.

pub mod cluster_assign_cpu;
pub mod cluster_build;
pub mod compute_lighting;
pub mod deferred_subpass;
pub mod forward;
pub mod gbuffer;
pub mod omni_shadow;
pub mod shadow_map_view;
pub mod tone_map;

use crate::pass::Pass;
use crate::scene_gpu::SceneGpu;
use crate::settings::{DebugView, LightAssignment, LightingStage, RenderSettings, Shading, ShadingModel};
use ml_cpu::gpu_types::PointLight;
use ml_vk::{vk, Context, VkError};

/// What the passes of a technique are made for.
pub struct Assembly<'a> {
    pub settings: &'a RenderSettings,
    pub shading: Shading,
    /// The scene's lights at rest (the GPU build animates them).
    pub lights: &'a [PointLight],
    pub scene: &'a SceneGpu,
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
    if a.scene.omni.active() {
        passes.push(Box::new(omni_shadow::OmniShadowPass));
    }
    match technique.assignment() {
        LightAssignment::None => {}
        LightAssignment::Cpu => passes.push(Box::<cluster_assign_cpu::CpuClusterAssign>::default()),
        LightAssignment::Gpu => passes.push(Box::new(cluster_build::ClusterBuild::new(ctx, a.lights, s.clusters.count())?)),
    }
    match technique.lighting_stage() {
        LightingStage::Forward => {
            let legend = s.debug_view == DebugView::ClusterHeat;
            passes.push(Box::new(forward::Forward::new(ctx, a.scene, raster, (clustered, legend), technique.name())?));
        }
        LightingStage::Subpass => {
            passes.push(Box::new(deferred_subpass::DeferredSubpasses::new(ctx, a.scene, raster, clustered)?));
            // pbr's curve, not for surface views (their values are shown as they are).
            let surface_view = !matches!(s.debug_view, DebugView::None | DebugView::ClusterHeat);
            passes.push(Box::new(tone_map::ToneMap::new(ctx, s.shading == ShadingModel::Pbr && !surface_view)?));
        }
        LightingStage::Compute => {
            passes.push(Box::new(gbuffer::GBuffer::new(ctx, a.scene, raster)?));
            passes.push(Box::new(compute_lighting::ComputeLighting::new(ctx, a.scene, a.shading)?));
        }
    }
    if matches!(s.debug_view, DebugView::ShadowMap | DebugView::ShadowCube) {
        passes.push(Box::new(shadow_map_view::ShadowMapView::new(ctx, a.scene, s.debug_view == DebugView::ShadowCube)?));
    }
    Ok(())
}
