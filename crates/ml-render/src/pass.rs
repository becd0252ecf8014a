//! What every pass of a frame is to the renderer. A technique is an ordered list of passes
//! (`plan::plan`, made by `assembly::assemble`); the renderer loops over it to bind,
//! prepare, order (`uses`), record, time and collect, and knows no pass by name. Each pass owns its pipelines, its per-frame descriptor sets (and
//! framebuffers) and rewrites them when a frame slot's buffers or targets change.

use crate::error::RenderError;
use crate::frame_resources::FrameResources;
use crate::read_back::HostRead;
use crate::report::FrameStats;
use crate::scene::SceneGpu;
use crate::sync::{BufferName, Use};
use crate::targets::Targets;
use ml_cpu::camera::View;
use ml_cpu::cluster::{ClusterGrid, ClusterLists, ClusterStats};
use ml_cpu::gpu_types::PointLight;
use ml_vk::{vk, Context, VkError};

/// What a pass records with.
pub struct Recording<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub slot: usize,
    pub extent: vk::Extent2D,
    pub targets: &'a Targets,
    pub scene: &'a SceneGpu,
    pub objects: &'a [ml_cpu::scene::Object],
    /// The frame's camera, world → clip (the uniforms' `proj · view`).
    pub view_proj: glam::Mat4,
}

/// What a frame slot's finished frame tells the frame loop: the GPU light assignment's top of
/// the heat map and the exposure meter's reading (the next frame's EV). Statistics go to
/// `FrameStats` directly.
#[derive(Clone, Copy, Debug, Default)]
pub struct SlotReport {
    /// The most lights a fragment may test (the cluster-heat view's top).
    pub max_lights: Option<u32>,
    /// Auto exposure: the log2 of its image's log-average luminance before exposure (None: not
    /// metered, or nothing but background).
    pub log2_luminance: Option<f32>,
}

/// The CPU side of a frame, before it is recorded (`Pass::prepare`): what a pass's CPU step
/// reads (the frame's view, lights and grid) and may change (the slot's light lists, the
/// frame's statistics); state a feature keeps across frames (the shadow atlas's cache) is
/// its own.
pub struct Prepare<'a> {
    pub ctx: &'a Context,
    /// The frame slot the frame is recorded into.
    pub slot: usize,
    pub grid: &'a ClusterGrid,
    /// The camera and image size the frame is seen through.
    pub view: &'a View,
    /// The scene's lights at rest, and how far the animation moves them this frame (every
    /// light by the same offset).
    pub rest_lights: &'a [PointLight],
    pub light_offset: glam::Vec3,
    /// This frame's animated lights where the CPU animates them (empty where the GPU does).
    pub lights: &'a [PointLight],
    /// The slot's lists (written, grown by the renderer where they are too short).
    pub lists: &'a mut dyn ListUpload,
    pub stats: &'a mut FrameStats,
    /// A CPU light assignment's milliseconds and what it built (the renderer reports the
    /// time as its own CPU phase and scales the cluster heat map by the fullest cluster).
    pub assigned: Option<(f64, ClusterStats)>,
    /// Set by a pass that replaced a buffer of the slot (grew it): the renderer binds every
    /// pass to the slot's buffers again before recording.
    pub rebind: bool,
}

/// Where a CPU assignment's lists go: the frame slot's buffers.
pub trait ListUpload {
    fn upload(&mut self, ctx: &Context, lists: &ClusterLists) -> Result<(), RenderError>;
    /// The most entries the slot's list may ever hold (what the device binds).
    fn max_entries(&self, ctx: &Context) -> usize;
}

/// What a pass is to the frame's recording: its pipelines and sets, what it reads and writes,
/// its commands. What it does around the recording — a CPU step, buffers per frame slot,
/// read-backs, figures, uniforms — is its `FrameWork`, where it has any.
pub trait Pass {
    /// Name in the timing table; None: untimed (debug views, CPU work).
    fn timer_name(&self) -> Option<&'static str>;

    /// (Re)point this pass's sets (and framebuffers) of `frame.slot` at that slot's buffers
    /// and targets: when the slot is made and when its buffers grow. Only while the slot is
    /// not in flight.
    fn bind_frame(&mut self, ctx: &Context, frame: &FrameResources) -> Result<(), VkError>;

    /// What the pass reads and writes of the frame's named resources, and in which stages:
    /// before the pass the renderer records the barrier that orders these after their
    /// earlier uses (`sync`). A resource is either declared by every pass that uses it or by
    /// none (each then orders its own uses, as the culling's buffers still are).
    fn uses(&self) -> Vec<Use> {
        Vec::new()
    }

    /// Record the pass into a frame's command buffer.
    fn record(&self, rec: &Recording);

    fn destroy(&mut self, ctx: &Context);

    /// Its work around the recording (`Some(self)` where it implements `FrameWork`).
    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        None
    }
}

/// What a pass does around the frame's recording, each step called by the renderer at its
/// time in the frame (docs/architecture.md, "Adding a feature"): most passes do none of it.
pub trait FrameWork {
    /// The pass's CPU step for a frame, before the frame is recorded (lights assigned on the
    /// CPU, the shadowed lights placed and the shadow atlas planned): what `record` then
    /// draws from.
    fn prepare(&mut self, _prepare: &mut Prepare) -> Result<(), RenderError> {
        Ok(())
    }

    /// Make the pass's own buffers of frame slot `slot` for images of `extent`, replacing any
    /// it had (no frame in flight): when the renderer makes the slot, before any pass binds it.
    fn create_slot(&mut self, _ctx: &Context, _slot: usize, _extent: vk::Extent2D) -> Result<(), VkError> {
        Ok(())
    }

    /// The pass's own buffers of slot `slot` under the names the shaders give them: the slot's
    /// table of resources holds them for every pass (`FrameResources`).
    fn slot_buffers(&self, _slot: usize) -> Vec<(BufferName, vk::Buffer)> {
        Vec::new()
    }

    /// What the host reads of slot `slot`'s resources once its frame is done (in `collect`):
    /// after every pass the renderer orders them, copies those in device memory into their
    /// `ReadBack` and makes them visible to the host (`read_back`).
    fn host_reads(&self, _slot: usize) -> Vec<HostRead> {
        Vec::new()
    }

    /// Read what slot `slot`'s finished frame reports (its fence has signalled): feedback for
    /// the frame loop into `report`, the pass's own figures into `stats`.
    fn collect(&self, _slot: usize, _report: &mut SlotReport, _stats: &mut FrameStats) {}

    /// Whether slot `slot`'s finished frame did some of its work the slow way, which the
    /// slot's next frame will not (a list it overflowed grows in `prepare`): a render's last
    /// frame is then drawn again.
    fn redraws(&self, _ctx: &Context, _slot: usize) -> bool {
        false
    }

    /// Fill the frame's uniforms that the pass owns (the light grid's placement), the lights
    /// moved by `light_offset` this frame.
    fn frame_uniforms(&self, _uniforms: &mut ml_cpu::gpu_types::FrameUniforms, _light_offset: glam::Vec3) {}
}
