//! Headless rendering (SPEC §5): offscreen targets, frames in flight, a read-back of the
//! last frame into host memory. No window system needed.

use crate::error::RenderError;
use crate::forward::ForwardPass;
use crate::frame::{FrameInFlight, FrameSetup, FRAMES_IN_FLIGHT};
use crate::gpu_mesh::GpuMesh;
use crate::report::FrameStats;
use crate::settings::RenderSettings;
use crate::targets::{depth_format, Targets};
use crate::settings::DebugView;
use ml_cpu::cluster::{ClusterAssigner, ClusterGrid, ClusterLists};
use ml_cpu::gpu_types::{FrameUniforms, PointLight, DEBUG_VIEW_CLUSTER_HEAT, DEBUG_VIEW_NONE, SHADING_SEED};
use ml_cpu::lights::animate_into;
use ml_cpu::scene::Scene;
use ml_vk::{commands, vk, Buffer, Context, VkError, VkResultExt};
use std::time::Instant;

/// CPU-side cluster state of `clustered-cpu`: the grid (rebuilt when camera or size change;
/// fixed in headless rendering), the assigner and this frame's lists.
struct CpuClusters {
    grid: ClusterGrid,
    assigner: ClusterAssigner,
    lists: ClusterLists,
}

/// A rendered image (tightly packed RGBA8, row 0 at the top) and its measurements.
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub stats: FrameStats,
}

pub struct HeadlessRenderer<'a> {
    ctx: &'a Context,
    scene: Scene,
    settings: RenderSettings,
    extent: vk::Extent2D,
    pass: ForwardPass,
    meshes: Vec<GpuMesh>,
    command_pool: vk::CommandPool,
    descriptor_pool: vk::DescriptorPool,
    frames: Vec<FrameInFlight>,
    readback: Option<Buffer>,
    /// Lights of the current frame (animated copy of the scene's).
    animated: Vec<PointLight>,
    clusters: Option<CpuClusters>,
    /// The cluster grid's shader parameters (also set for `forward`, which ignores them).
    grid: ClusterGrid,
}

impl<'a> HeadlessRenderer<'a> {
    pub fn new(ctx: &'a Context, scene: Scene, settings: RenderSettings) -> Result<HeadlessRenderer<'a>, RenderError> {
        settings.check(ctx, scene.lights.len())?;
        let depth = depth_format(ctx)?;
        let extent = vk::Extent2D { width: settings.width, height: settings.height };
        let animated = scene.lights.clone();
        let grid = ClusterGrid::new(settings.clusters, settings.width, settings.height, &scene.camera);
        let clusters = settings.technique.is_clustered().then(|| CpuClusters {
            grid: grid.clone(),
            assigner: ClusterAssigner::new(),
            lists: ClusterLists::default(),
        });
        let mut r = HeadlessRenderer {
            ctx,
            scene,
            settings,
            extent,
            pass: ForwardPass::new(ctx, depth, settings.technique)?,
            meshes: Vec::new(),
            command_pool: vk::CommandPool::null(),
            descriptor_pool: vk::DescriptorPool::null(),
            frames: Vec::new(),
            readback: None,
            animated,
            clusters,
            grid,
        };
        // Anything made before a failure is released by Drop.
        r.create_resources(depth)?;
        Ok(r)
    }

    fn create_resources(&mut self, depth: vk::Format) -> Result<(), VkError> {
        let ctx = self.ctx;
        for kind in self.scene.mesh_kinds() {
            self.meshes.push(GpuMesh::upload(ctx, kind, &kind.build())?);
        }
        let pool_info = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        // SAFETY: valid device and create infos.
        self.command_pool = unsafe { ctx.device.create_command_pool(&pool_info, None) }.ctx("vkCreateCommandPool")?;
        let n = FRAMES_IN_FLIGHT as u32;
        let sizes = [
            vk::DescriptorPoolSize { ty: vk::DescriptorType::UNIFORM_BUFFER, descriptor_count: n },
            vk::DescriptorPoolSize { ty: vk::DescriptorType::STORAGE_BUFFER, descriptor_count: 3 * n },
        ];
        let dp_info = vk::DescriptorPoolCreateInfo::default().max_sets(n).pool_sizes(&sizes);
        // SAFETY: as above.
        self.descriptor_pool = unsafe { ctx.device.create_descriptor_pool(&dp_info, None) }.ctx("vkCreateDescriptorPool")?;
        let render_pass = self.pass.render_pass;
        let extent = self.extent;
        let make_targets = || Targets::new(ctx, render_pass, extent, depth);
        let setup = FrameSetup {
            pool: self.command_pool,
            descriptor_pool: self.descriptor_pool,
            set_layout: self.pass.set_layout,
            light_count: self.scene.lights.len(),
            cluster_count: self.settings.clusters.count(),
            passes: 1,
            make_targets: &make_targets,
        };
        for _ in 0..FRAMES_IN_FLIGHT {
            self.frames.push(FrameInFlight::new(ctx, &setup)?);
        }
        let bytes = extent.width as u64 * extent.height as u64 * 4;
        self.readback = Some(Buffer::new(ctx, "read-back", bytes, vk::BufferUsageFlags::TRANSFER_DST, gpu_allocator::MemoryLocation::GpuToCpu)?);
        Ok(())
    }

    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Render `settings.frames` frames, two in flight, and read back the last one.
    pub fn render(&mut self) -> Result<RenderOutput, RenderError> {
        let ctx = self.ctx;
        let mut stats = FrameStats::new(&[self.settings.technique.name()]);
        let start = Instant::now();
        let mut last = 0;
        for i in 0..self.settings.frames {
            let f = i as usize % FRAMES_IN_FLIGHT;
            let fence = self.frames[f].fence;
            // SAFETY: the fence belongs to this device.
            unsafe { ctx.device.wait_for_fences(&[fence], true, u64::MAX) }.ctx("vkWaitForFences")?;
            if let Some(ms) = self.frames[f].timer.read_ms(ctx)? {
                stats.add_gpu(&ms);
            }
            let cpu = Instant::now();
            self.update_frame(f, self.settings.clock(i), &mut stats)?;
            self.record(f)?;
            // SAFETY: the fence was waited on above and the command buffer is executable.
            unsafe {
                ctx.device.reset_fences(&[fence]).ctx("vkResetFences")?;
                let cmds = [self.frames[f].cmd];
                let submit = [vk::SubmitInfo::default().command_buffers(&cmds)];
                ctx.device.queue_submit(ctx.queue, &submit, fence).ctx("vkQueueSubmit")?;
            }
            stats.add_cpu_ms(cpu.elapsed().as_secs_f64() * 1e3);
            last = f;
        }
        for f in 0..FRAMES_IN_FLIGHT {
            // SAFETY: as above.
            unsafe { ctx.device.wait_for_fences(&[self.frames[f].fence], true, u64::MAX) }.ctx("vkWaitForFences")?;
            if let Some(ms) = self.frames[f].timer.read_ms(ctx)? {
                stats.add_gpu(&ms);
            }
        }
        stats.wall_ms = start.elapsed().as_secs_f64() * 1e3;
        stats.frames = self.settings.frames;
        let rgba = self.read_back(last)?;
        Ok(RenderOutput { width: self.extent.width, height: self.extent.height, rgba, stats })
    }

    fn update_frame(&mut self, f: usize, t: f32, stats: &mut FrameStats) -> Result<(), VkError> {
        animate_into(&self.scene.lights, t, &mut self.animated);
        let mut heat_top = 1.0;
        if let Some(c) = &mut self.clusters {
            let start = Instant::now();
            c.assigner.assign(&c.grid, &self.animated, &mut c.lists);
            stats.add_assign_ms(start.elapsed().as_secs_f64() * 1e3);
            let cluster_stats = c.lists.stats();
            heat_top = cluster_stats.max_lights.max(1) as f32;
            stats.clusters = Some(cluster_stats);
            if self.frames[f].upload_clusters(self.ctx, &c.lists)? {
                stats.index_growths += 1;
            }
        }
        let g = &self.grid;
        let debug_view = match self.settings.debug_view {
            DebugView::None => DEBUG_VIEW_NONE,
            DebugView::ClusterHeat => DEBUG_VIEW_CLUSTER_HEAT,
        };
        let cam = &self.scene.camera;
        let uniforms = FrameUniforms {
            view: cam.view().to_cols_array_2d(),
            proj: cam.projection(self.extent.width as f32 / self.extent.height as f32).to_cols_array_2d(),
            camera_pos: cam.position.extend(1.0).to_array(),
            light_count: self.animated.len() as u32,
            ambient: self.scene.ambient,
            shading_model: SHADING_SEED,
            _pad0: 0,
            cluster_dims: [g.dims.x, g.dims.y, g.dims.z, debug_view],
            viewport: [self.extent.width, self.extent.height, 0, 0],
            cluster_slices: [g.log_scale, g.log_bias, heat_top, 0.0],
        };
        let frame = &mut self.frames[f];
        frame.uniforms.write(0, &[uniforms]);
        frame.lights.write(0, &self.animated);
        Ok(())
    }

    fn record(&mut self, f: usize) -> Result<(), VkError> {
        let ctx = self.ctx;
        let frame = &mut self.frames[f];
        let cmd = frame.cmd;
        // SAFETY: the frame's fence has signalled, so the command buffer is not pending.
        unsafe {
            ctx.device.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty()).ctx("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            ctx.device.begin_command_buffer(cmd, &begin).ctx("vkBeginCommandBuffer")?;
        }
        frame.timer.reset(ctx, cmd);
        frame.timer.begin(ctx, cmd, 0);
        let framebuffer = frame.targets.as_ref().expect("made with the frame").framebuffer;
        let legend = self.settings.debug_view == DebugView::ClusterHeat;
        self.pass.record(ctx, cmd, framebuffer, self.extent, frame.set, &self.meshes, &self.scene.objects, legend);
        frame.timer.end(ctx, cmd, 0);
        // SAFETY: recording state.
        unsafe { ctx.device.end_command_buffer(cmd) }.ctx("vkEndCommandBuffer")
    }

    /// Copy frame `f`'s colour target (left in TRANSFER_SRC_OPTIMAL by the render pass, whose
    /// outgoing dependency orders this copy after the colour writes) into host memory.
    fn read_back(&mut self, f: usize) -> Result<Vec<u8>, VkError> {
        let ctx = self.ctx;
        let image = self.frames[f].targets.as_ref().expect("made with the frame").color.raw;
        let buffer = self.readback.as_ref().expect("created with the renderer");
        let extent = self.extent;
        commands::one_shot(ctx, |cmd| {
            let region = [vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1))
                .image_extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })];
            let to_host = [vk::BufferMemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::HOST_READ)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .buffer(buffer.raw)
                .size(vk::WHOLE_SIZE)];
            // SAFETY: recording state; image and buffer are alive and large enough.
            unsafe {
                ctx.device.cmd_copy_image_to_buffer(cmd, image, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, buffer.raw, &region);
                ctx.device.cmd_pipeline_barrier(
                    cmd,
                    vk::PipelineStageFlags::TRANSFER,
                    vk::PipelineStageFlags::HOST,
                    vk::DependencyFlags::empty(),
                    &[],
                    &to_host,
                    &[],
                );
            }
        })?;
        Ok(buffer.mapped().to_vec())
    }
}

impl Drop for HeadlessRenderer<'_> {
    fn drop(&mut self) {
        let ctx = self.ctx;
        let _ = ctx.wait_idle();
        for frame in &mut self.frames {
            frame.destroy(ctx);
        }
        if let Some(mut b) = self.readback.take() {
            b.destroy(ctx);
        }
        for mesh in &mut self.meshes {
            mesh.destroy(ctx);
        }
        // SAFETY: the device is idle; null handles are ignored.
        unsafe {
            ctx.device.destroy_descriptor_pool(self.descriptor_pool, None);
            ctx.device.destroy_command_pool(self.command_pool, None);
        }
        self.pass.destroy(ctx);
    }
}
