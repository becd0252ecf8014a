//! GPU pass timing with timestamp queries: one pool per frame in flight, two queries per pass.

use crate::context::Context;
use crate::error::{Result, VkResultExt};
use ash::vk;

pub struct GpuTimer {
    pool: vk::QueryPool,
    passes: u32,
    /// Nanoseconds per tick; None when the queue has no timestamps.
    period_ns: Option<f64>,
    written: bool,
}

impl GpuTimer {
    pub fn new(ctx: &Context, passes: u32) -> Result<GpuTimer> {
        let info = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(passes * 2);
        // SAFETY: valid device.
        let pool = unsafe { ctx.device.create_query_pool(&info, None) }.ctx("vkCreateQueryPool")?;
        let period_ns = (ctx.timestamp_valid_bits > 0).then_some(ctx.info.limits.timestamp_period as f64);
        Ok(GpuTimer { pool, passes, period_ns, written: false })
    }

    /// A timer that owns nothing (a placeholder while a larger object is being built).
    pub fn null() -> GpuTimer {
        GpuTimer { pool: vk::QueryPool::null(), passes: 0, period_ns: None, written: false }
    }

    /// Reset all queries; record outside a render pass before the first `begin`.
    pub fn reset(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        // SAFETY: recording state, outside a render pass.
        unsafe { ctx.device.cmd_reset_query_pool(cmd, self.pool, 0, self.passes * 2) };
        self.written = self.period_ns.is_some();
    }

    pub fn begin(&self, ctx: &Context, cmd: vk::CommandBuffer, pass: u32) {
        if self.period_ns.is_some() {
            // SAFETY: query index within the pool, reset earlier in this command buffer.
            unsafe { ctx.device.cmd_write_timestamp(cmd, vk::PipelineStageFlags::TOP_OF_PIPE, self.pool, pass * 2) };
        }
    }

    /// Close pass `pass`. A timed compute pass must end with a barrier inside the pass:
    /// lavapipe (Mesa 22.3) writes a timestamp after a dispatch as soon as the work is queued
    /// rather than done (measured: 0.03 ms for a 150 ms dispatch), and a barrier makes it
    /// finish first. On other devices BOTTOM_OF_PIPE waits for every earlier command anyway.
    pub fn end(&self, ctx: &Context, cmd: vk::CommandBuffer, pass: u32) {
        if self.period_ns.is_some() {
            // SAFETY: as in `begin`.
            unsafe { ctx.device.cmd_write_timestamp(cmd, vk::PipelineStageFlags::BOTTOM_OF_PIPE, self.pool, pass * 2 + 1) };
        }
    }

    /// Milliseconds per pass of the last submitted frame; call after its fence signalled.
    /// None when the device has no timestamps or nothing was recorded yet.
    pub fn read_ms(&mut self, ctx: &Context) -> Result<Option<Vec<f64>>> {
        let Some(period) = self.period_ns.filter(|_| self.written) else { return Ok(None) };
        let mut ticks = vec![0u64; (self.passes * 2) as usize];
        // SAFETY: all queries were written by a command buffer whose fence has signalled.
        unsafe { ctx.device.get_query_pool_results(self.pool, 0, &mut ticks, vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT) }
            .ctx("vkGetQueryPoolResults")?;
        self.written = false;
        let mask = if ctx.timestamp_valid_bits >= 64 { u64::MAX } else { (1u64 << ctx.timestamp_valid_bits) - 1 };
        Ok(Some(ticks.chunks_exact(2).map(|t| ((t[1] & mask).wrapping_sub(t[0] & mask) & mask) as f64 * period / 1e6).collect()))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        // SAFETY: no command buffer using the pool is pending.
        unsafe { ctx.device.destroy_query_pool(self.pool, None) };
        self.pool = vk::QueryPool::null();
    }
}
