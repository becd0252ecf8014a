//! Light assignment on the CPU (techniques clustered-cpu, deferred-clustered;
//! docs/DESIGN.md#clustered-light-assignment): every frame, before it is recorded, the
//! animated lights are assigned to the clusters (ml_cpu::cluster, multi-threaded) and the
//! lists uploaded into the frame slot's buffers. No GPU work of its own.

use crate::error::RenderError;
use crate::frame::lists_too_long;
use crate::frame_resources::FrameResources;
use crate::pass::{FrameWork, Pass, Prepare, Recording};
use ml_cpu::cluster::{ClusterAssigner, ClusterLists};
use ml_vk::{Context, VkError};
use std::time::Instant;

/// Most light-index entries the CPU builds (512 MiB of indices, twice that while assigning);
/// beyond it the render fails with a clear message.
const MAX_CPU_LIST_ENTRIES: usize = 1 << 27;

#[derive(Default)]
pub struct CpuClusterAssign {
    assigner: ClusterAssigner,
    lists: ClusterLists,
}

impl Pass for CpuClusterAssign {
    fn timer_name(&self) -> Option<&'static str> {
        None
    }

    fn bind_frame(&mut self, _: &Context, _: &FrameResources) -> Result<(), VkError> {
        Ok(())
    }

    fn record(&self, _: &Recording) {}

    fn destroy(&mut self, _: &Context) {}

    fn frame_work(&mut self) -> Option<&mut dyn FrameWork> {
        Some(self)
    }
}

impl FrameWork for CpuClusterAssign {
    fn prepare(&mut self, up: &mut Prepare) -> Result<(), RenderError> {
        let start = Instant::now();
        // The CPU also holds the lists (and their pairs) in memory: cap what it builds.
        let limit = up.lists.max_entries(up.ctx).min(MAX_CPU_LIST_ENTRIES);
        self.assigner
            .assign(up.grid, up.lights, &mut self.lists, limit)
            .map_err(|e| lists_too_long(e.at_least, limit, "the CPU assignment builds (or the device binds)"))?;
        let ms = start.elapsed().as_secs_f64() * 1e3;
        up.lists.upload(up.ctx, &self.lists)?;
        up.assigned = Some((ms, self.lists.stats()));
        Ok(())
    }
}
