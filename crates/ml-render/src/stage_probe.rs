//! The compute-vs-fragment probe (`manylights bench --probe`, `--technique auto`): the same
//! BRDF loop (stage_probe.glsl) over the same pixels as a fragment shader (a full-screen
//! triangle into a colour attachment) and as a compute shader (8×8 groups into a storage
//! image of the same format), each timed alone with timestamps. Devices differ by an order of
//! magnitude here — the H100/H200 run graphics shaders on 4 of their 132 SMs — so which
//! lighting path is fastest is measured, not assumed.

use crate::descriptors::{self, Resource, SetLayout};
use crate::report::Spread;
use crate::specialization::compute_pipeline;
use crate::technique::Technique;
use ml_cpu::gpu_types::{PointLight, StageProbePush};
use ml_shaders::{FULLSCREEN_VERT, STAGE_PROBE_COMP, STAGE_PROBE_FRAG};
use ml_vk::commands::{copy_colour_to_host, one_shot};
use ml_vk::descriptors::allocate_set;
use ml_vk::image::image_transition;
use ml_vk::{shader, vk, Buffer, Context, GpuTimer, Image, MemoryLocation, VkError, VkResultExt};
use std::time::Instant;

/// Both halves write this 8-bit format, so their images can be compared byte for byte.
const FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;

/// One kind of pass's time for one loop length.
#[derive(Clone, Copy, Debug)]
pub struct StageTimes {
    /// Lights every pixel sums.
    pub lights: u32,
    pub pixels: u64,
    /// Milliseconds per pass over the measured repeats.
    pub fragment: Spread,
    pub compute: Spread,
    /// GPU timestamps, or (devices without them) wall time around each submission.
    pub timestamps: bool,
}

impl StageTimes {
    /// How many times longer the fragment shader takes than the compute shader (medians).
    pub fn ratio(&self) -> f64 {
        self.fragment.median / self.compute.median
    }
}

/// Above this ratio the compute lighting path wins by more than what the measurement can
/// blur (repeats of one run on lavapipe spread by under 10 %); below its inverse the fragment
/// shader does, and deferred shading stays in the render pass as a subpass; in between the
/// probe cannot choose (`too_close_to_call`).
pub const COMPUTE_WINS_ABOVE: f64 = 1.25;

/// The lighting path `--technique auto` takes on a device whose probe measured `times` (and
/// which can run the meshlet techniques, or not), and why. The candidates are exact and cull
/// lights by the same clusters; they differ in the kind of pass that runs the light loop
/// (compute: `visibility`, whose GPU-culled geometry also beat the G-buffer pass wherever it
/// was measured, else `deferred-compute`; the render pass's second subpass:
/// `deferred-clustered`, whose G-buffer reads stay on chip on tiled GPUs). Where the probe is
/// `too_close_to_call`, this says deferred-clustered, and `--technique auto` lets the scene
/// decide.
pub fn pick_lighting_path(times: &StageTimes, meshlets: bool) -> (Technique, String) {
    let ratio = times.ratio();
    let technique = match (ratio > COMPUTE_WINS_ABOVE, meshlets) {
        (true, true) => Technique::Visibility,
        (true, false) => Technique::DeferredCompute,
        (false, _) => Technique::DeferredClustered,
    };
    let why = format!(
        "the probe's light loop ({} px × {} lights) took {:.3} ms as a fragment shader and {:.3} ms as a compute shader \
         ({ratio:.2}×; compute wins above {COMPUTE_WINS_ABOVE}×)",
        times.pixels, times.lights, times.fragment.median, times.compute.median
    );
    (technique, why)
}

/// Whether neither kind of pass wins by more than COMPUTE_WINS_ABOVE (a CPU driver, where
/// both run on the same cores; any device whose fragment and compute units are the same): the
/// probe alone cannot choose there (`--technique auto` then renders the scene with each).
pub fn too_close_to_call(times: &StageTimes) -> bool {
    let ratio = times.ratio();
    ratio <= COMPUTE_WINS_ABOVE && ratio * COMPUTE_WINS_ABOVE >= 1.0
}

/// Deterministic lights over the probe's floor, every one reaching every pixel (radius 1 km
/// against a 40 m floor), colours scaled so that the sum stays in range.
pub fn probe_lights(count: u32) -> Vec<PointLight> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        // splitmix64: enough for spreading lights, no dependency.
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    };
    let strength = 40.0 / count.max(1) as f32;
    (0..count)
        .map(|_| PointLight {
            position_radius: [next() * 40.0 - 20.0, 1.0 + next() * 7.0, next() * 40.0 - 20.0, 1000.0],
            color: [strength * (0.5 + next()), strength * (0.5 + next()), strength * (0.5 + next()), 0.0],
        })
        .collect()
}

/// The probe's Vulkan objects for one image size and up to `max_lights` lights.
pub struct StageProbe {
    extent: vk::Extent2D,
    max_lights: u32,
    lights: Buffer,
    fragment_target: Image,
    compute_target: Image,
    render_pass: vk::RenderPass,
    framebuffer: vk::Framebuffer,
    fragment_set_layout: SetLayout,
    compute_set_layout: SetLayout,
    fragment_layout: vk::PipelineLayout,
    compute_layout: vk::PipelineLayout,
    fragment_pipeline: vk::Pipeline,
    compute_pipeline: vk::Pipeline,
    pool: vk::DescriptorPool,
    fragment_set: vk::DescriptorSet,
    compute_set: vk::DescriptorSet,
    timer: GpuTimer,
}

impl ml_vk::Release for StageProbe {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

impl StageProbe {
    pub fn new(ctx: &Context, width: u32, height: u32, max_lights: u32) -> Result<StageProbe, VkError> {
        ml_vk::build(ctx, StageProbe::empty(vk::Extent2D { width, height }, max_lights), |p| p.create(ctx))
    }

    /// A probe that owns nothing yet (or any more): every handle null.
    fn empty(extent: vk::Extent2D, max_lights: u32) -> StageProbe {
        StageProbe {
            extent,
            max_lights,
            lights: Buffer::null(),
            fragment_target: Image::null(),
            compute_target: Image::null(),
            render_pass: vk::RenderPass::null(),
            framebuffer: vk::Framebuffer::null(),
            fragment_set_layout: SetLayout::null(),
            compute_set_layout: SetLayout::null(),
            fragment_layout: vk::PipelineLayout::null(),
            compute_layout: vk::PipelineLayout::null(),
            fragment_pipeline: vk::Pipeline::null(),
            compute_pipeline: vk::Pipeline::null(),
            pool: vk::DescriptorPool::null(),
            fragment_set: vk::DescriptorSet::null(),
            compute_set: vk::DescriptorSet::null(),
            timer: GpuTimer::null(),
        }
    }

    fn create(&mut self, ctx: &Context) -> Result<(), VkError> {
        let d = &ctx.device;
        let lights = probe_lights(self.max_lights);
        self.lights = Buffer::device_local_with(ctx, "probe lights", bytemuck::cast_slice(&lights), vk::BufferUsageFlags::STORAGE_BUFFER)?;
        let usage = vk::ImageUsageFlags::TRANSFER_SRC;
        let aspect = vk::ImageAspectFlags::COLOR;
        self.fragment_target =
            Image::new_2d(ctx, "probe fragment target", self.extent, FORMAT, usage | vk::ImageUsageFlags::COLOR_ATTACHMENT, aspect)?;
        self.compute_target =
            Image::new_2d(ctx, "probe compute target", self.extent, FORMAT, usage | vk::ImageUsageFlags::STORAGE, aspect)?;
        self.render_pass = render_pass(ctx)?;
        let attachments = [self.fragment_target.view];
        let info = vk::FramebufferCreateInfo::default()
            .render_pass(self.render_pass)
            .attachments(&attachments)
            .width(self.extent.width)
            .height(self.extent.height)
            .layers(1);
        // SAFETY: the render pass and view are alive and match.
        self.framebuffer = unsafe { d.create_framebuffer(&info, None) }.ctx("vkCreateFramebuffer")?;

        // Set 0 of each half as its shaders declare it (stage_probe.glsl's lights, the compute
        // half's output image).
        let fragment_stages = [(&FULLSCREEN_VERT, vk::ShaderStageFlags::VERTEX), (&STAGE_PROBE_FRAG, vk::ShaderStageFlags::FRAGMENT)];
        self.fragment_set_layout = SetLayout::new(ctx, &fragment_stages, 0)?;
        self.compute_set_layout = SetLayout::new(ctx, &[(&STAGE_PROBE_COMP, vk::ShaderStageFlags::COMPUTE)], 0)?;
        let push = |stage| [vk::PushConstantRange::default().stage_flags(stage).size(std::mem::size_of::<StageProbePush>() as u32)];
        self.fragment_layout = shader::pipeline_layout(ctx, &[self.fragment_set_layout.raw], &push(vk::ShaderStageFlags::FRAGMENT))?;
        self.compute_layout = shader::pipeline_layout(ctx, &[self.compute_set_layout.raw], &push(vk::ShaderStageFlags::COMPUTE))?;
        self.compute_pipeline = compute_pipeline(ctx, &STAGE_PROBE_COMP, self.compute_layout, &[])?;
        self.fragment_pipeline = shader::graphics_pipeline(
            ctx,
            &shader::GraphicsPipelineDesc {
                vertex: FULLSCREEN_VERT.spirv,
                vertex_constants: &[],
                fragment: Some(STAGE_PROBE_FRAG.spirv),
                fragment_constants: &[],
                vertex_input: vk::PipelineVertexInputStateCreateInfo::default(),
                rasterization: vk::PipelineRasterizationStateCreateInfo::default()
                    .polygon_mode(vk::PolygonMode::FILL)
                    .cull_mode(vk::CullModeFlags::NONE)
                    .line_width(1.0),
                depth_stencil: vk::PipelineDepthStencilStateCreateInfo::default(),
                colour_attachments: 1,
                samples: vk::SampleCountFlags::TYPE_1,
                layout: self.fragment_layout,
                render_pass: self.render_pass,
                subpass: 0,
            },
        )?;

        self.pool = descriptors::pool(ctx, &[(&self.fragment_set_layout, 1), (&self.compute_set_layout, 1)])?;
        self.fragment_set = allocate_set(ctx, self.pool, self.fragment_set_layout.raw)?;
        self.compute_set = allocate_set(ctx, self.pool, self.compute_set_layout.raw)?;
        let out = vk::DescriptorImageInfo::default().image_view(self.compute_target.view).image_layout(vk::ImageLayout::GENERAL);
        let lookup = |name: &str| match name {
            "ProbeLights" => Some(Resource::Buffer(self.lights.raw)),
            "out_image" => Some(Resource::Image(out)),
            _ => None,
        };
        self.fragment_set_layout.write(ctx, self.fragment_set, &lookup)?;
        self.compute_set_layout.write(ctx, self.compute_set, &lookup)?;
        self.timer = GpuTimer::new(ctx, 1)?;
        Ok(())
    }

    fn push(&self, lights: u32) -> StageProbePush {
        StageProbePush { size_lights: [self.extent.width, self.extent.height, lights, 0] }
    }

    /// Record the fragment half: the full-screen triangle, the target left for transfers.
    fn record_fragment(&self, ctx: &Context, cmd: vk::CommandBuffer, lights: u32) {
        let d = &ctx.device;
        let area = vk::Rect2D { offset: vk::Offset2D::default(), extent: self.extent };
        let begin = vk::RenderPassBeginInfo::default().render_pass(self.render_pass).framebuffer(self.framebuffer).render_area(area);
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: self.extent.width as f32,
            height: self.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        // SAFETY: recording state; everything bound is alive; the push range matches the layout.
        unsafe {
            d.cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, self.fragment_pipeline);
            d.cmd_set_viewport(cmd, 0, &[viewport]);
            d.cmd_set_scissor(cmd, 0, &[area]);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.fragment_layout, 0, &[self.fragment_set], &[]);
            d.cmd_push_constants(cmd, self.fragment_layout, vk::ShaderStageFlags::FRAGMENT, 0, bytemuck::bytes_of(&self.push(lights)));
            d.cmd_draw(cmd, 3, 1, 0, 0);
            d.cmd_end_render_pass(cmd);
        }
    }

    /// Record the compute half with its layout transitions, as the render pass of the fragment
    /// half makes its own (the barrier after the dispatch also makes lavapipe finish the
    /// dispatch before the closing timestamp, which it otherwise writes as soon as the work
    /// is queued: measured 0.03 ms for 150 ms of work).
    fn record_compute(&self, ctx: &Context, cmd: vk::CommandBuffer, lights: u32) {
        let d = &ctx.device;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let storage = (compute, vk::AccessFlags::SHADER_WRITE, vk::ImageLayout::GENERAL);
        // The image was last written by this pass or read by a copy, in earlier submissions.
        image_transition(
            ctx,
            cmd,
            self.compute_target.raw,
            (compute | transfer, vk::AccessFlags::SHADER_WRITE, vk::ImageLayout::UNDEFINED),
            storage,
        );
        // SAFETY: recording state outside a render pass; everything bound is alive.
        unsafe {
            d.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.compute_pipeline);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.compute_layout, 0, &[self.compute_set], &[]);
            d.cmd_push_constants(cmd, self.compute_layout, vk::ShaderStageFlags::COMPUTE, 0, bytemuck::bytes_of(&self.push(lights)));
            let [x, y, _] = STAGE_PROBE_COMP.groups([self.extent.width, self.extent.height, 1]);
            d.cmd_dispatch(cmd, x, y, 1);
        }
        let readable = (transfer, vk::AccessFlags::TRANSFER_READ, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        image_transition(ctx, cmd, self.compute_target.raw, storage, readable);
    }

    /// One submission of one half, its time in milliseconds.
    fn time_one(&mut self, ctx: &Context, fragment: bool, lights: u32) -> Result<f64, VkError> {
        // Out of `self` while recording, which borrows the rest of it.
        let mut timer = std::mem::replace(&mut self.timer, GpuTimer::null());
        let start = Instant::now();
        let submitted = one_shot(ctx, |cmd| {
            timer.reset(ctx, cmd);
            timer.begin(ctx, cmd, 0);
            if fragment {
                self.record_fragment(ctx, cmd, lights);
            } else {
                self.record_compute(ctx, cmd, lights);
            }
            timer.end(ctx, cmd, 0);
        });
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let read = submitted.and_then(|()| timer.read_ms(ctx));
        self.timer = timer;
        Ok(read?.map_or(wall_ms, |ms| ms[0]))
    }

    /// Time both halves summing `lights` lights: `warmup` unmeasured rounds, then `repeats`
    /// measured ones, the halves alternating so that clocks and caches treat them alike.
    pub fn measure(&mut self, ctx: &Context, lights: u32, warmup: u32, repeats: u32) -> Result<StageTimes, VkError> {
        assert!(lights <= self.max_lights && repeats > 0, "probe: {lights} lights of {}, {repeats} repeats", self.max_lights);
        let (mut fragment, mut compute) = (Vec::new(), Vec::new());
        for round in 0..warmup + repeats {
            let f = self.time_one(ctx, true, lights)?;
            let c = self.time_one(ctx, false, lights)?;
            if round >= warmup {
                fragment.push(f);
                compute.push(c);
            }
        }
        Ok(StageTimes {
            lights,
            pixels: u64::from(self.extent.width) * u64::from(self.extent.height),
            fragment: Spread::of(fragment),
            compute: Spread::of(compute),
            timestamps: ctx.timestamp_valid_bits > 0,
        })
    }

    /// The images the last measurement left: (fragment half, compute half), RGBA8 rows.
    pub fn read_images(&self, ctx: &Context) -> Result<(Vec<u8>, Vec<u8>), VkError> {
        let bytes = u64::from(self.extent.width) * u64::from(self.extent.height) * 4;
        let mut out = Vec::new();
        for image in [&self.fragment_target, &self.compute_target] {
            let mut host = Buffer::new(ctx, "probe read-back", bytes, vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
            let copied = one_shot(ctx, |cmd| copy_colour_to_host(ctx, cmd, image.raw, self.extent, host.raw));
            if copied.is_ok() {
                out.push(host.mapped()[..bytes as usize].to_vec());
            }
            host.destroy(ctx);
            copied?;
        }
        let compute = out.pop().expect("two images read");
        Ok((out.pop().expect("two images read"), compute))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        let d = &ctx.device;
        self.timer.destroy(ctx);
        // SAFETY: nothing is pending (every submission was waited for); null handles are ignored.
        unsafe {
            d.destroy_descriptor_pool(self.pool, None);
            ml_vk::shader::release_pipeline(ctx, self.fragment_pipeline);
            ml_vk::shader::release_pipeline(ctx, self.compute_pipeline);
            d.destroy_framebuffer(self.framebuffer, None);
        }
        self.fragment_set_layout.destroy(ctx);
        self.compute_set_layout.destroy(ctx);
        self.fragment_target.destroy(ctx);
        self.compute_target.destroy(ctx);
        self.lights.destroy(ctx);
        *self = StageProbe::empty(self.extent, self.max_lights);
    }
}

/// One colour attachment whose old contents do not matter, stored and left for a copy; the
/// dependencies order it after the previous submission's writes and copies of the image and
/// before the read-back.
fn render_pass(ctx: &Context) -> Result<vk::RenderPass, VkError> {
    let attachment = [vk::AttachmentDescription::default()
        .format(FORMAT)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::DONT_CARE)
        .store_op(vk::AttachmentStoreOp::STORE)
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
        .final_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL)];
    let colour = [vk::AttachmentReference { attachment: 0, layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL }];
    let subpass = [vk::SubpassDescription::default().pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS).color_attachments(&colour)];
    let output = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT;
    let write = vk::AccessFlags::COLOR_ATTACHMENT_WRITE;
    let dependencies = [
        vk::SubpassDependency::default()
            .src_subpass(vk::SUBPASS_EXTERNAL)
            .dst_subpass(0)
            .src_stage_mask(output | vk::PipelineStageFlags::TRANSFER)
            .src_access_mask(write)
            .dst_stage_mask(output)
            .dst_access_mask(write),
        vk::SubpassDependency::default()
            .src_subpass(0)
            .dst_subpass(vk::SUBPASS_EXTERNAL)
            .src_stage_mask(output)
            .src_access_mask(write)
            .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
            .dst_access_mask(vk::AccessFlags::TRANSFER_READ),
    ];
    let info = vk::RenderPassCreateInfo::default().attachments(&attachment).subpasses(&subpass).dependencies(&dependencies);
    ml_vk::shader::render_pass(ctx, &info)
}

/// `--technique auto`'s quick probe: 512×512 pixels, the loop made 4× longer from 16 lights
/// until the faster half takes a millisecond (or the slower one 100 ms, or 4,096 lights), so
/// that launch overheads do not decide; 1 + 3 rounds per length. Under a second on lavapipe.
pub fn quick_probe(ctx: &Context) -> Result<StageTimes, VkError> {
    const MAX_LIGHTS: u32 = 4096;
    let mut probe = StageProbe::new(ctx, 512, 512, MAX_LIGHTS)?;
    let result = (|| {
        // The loop length first: one pass of each kind per length.
        let mut lights = 16;
        loop {
            let t = probe.measure(ctx, lights, 0, 1)?;
            if t.fragment.median.min(t.compute.median) >= 1.0 || t.fragment.median.max(t.compute.median) >= 100.0 || lights >= MAX_LIGHTS {
                break;
            }
            lights *= 4;
        }
        // Then both kinds in turn until the GPU's clocks have risen, and the median of repeats.
        let start = Instant::now();
        let warm_up_s = if ctx.info.device_type == vk::PhysicalDeviceType::CPU { 0.0 } else { QUICK_WARM_UP_S };
        while start.elapsed().as_secs_f64() < warm_up_s {
            probe.measure(ctx, lights, 0, 1)?;
        }
        probe.measure(ctx, lights, 0, QUICK_REPEATS)
    })();
    probe.destroy(ctx);
    result
}

/// The quick probe's warm-up on a GPU: a GPU raises its clocks only under load (and lowers
/// them while the CPU loads a scene), so the measured repeats come after this much of it (on a
/// CPU driver none: the loop-length search's passes warmed it).
const QUICK_WARM_UP_S: f64 = 0.2;
/// The quick probe's repeats of each kind of pass; their medians are compared.
const QUICK_REPEATS: u32 = 5;

#[cfg(test)]
mod tests {
    use super::*;

    fn times(fragment: f64, compute: f64) -> StageTimes {
        let s = |ms| Spread { median: ms, p95: ms, mean: ms };
        StageTimes { lights: 256, pixels: 512 * 512, fragment: s(fragment), compute: s(compute), timestamps: true }
    }

    #[test]
    fn auto_takes_compute_only_where_it_clearly_wins() {
        assert_eq!(pick_lighting_path(&times(33.0, 1.0), true).0, Technique::Visibility);
        assert_eq!(pick_lighting_path(&times(33.0, 1.0), false).0, Technique::DeferredCompute);
        assert_eq!(pick_lighting_path(&times(1.3, 1.0), false).0, Technique::DeferredCompute);
        assert_eq!(pick_lighting_path(&times(1.2, 1.0), true).0, Technique::DeferredClustered);
        assert_eq!(pick_lighting_path(&times(1.0, 1.0), false).0, Technique::DeferredClustered);
        assert_eq!(pick_lighting_path(&times(0.5, 1.0), true).0, Technique::DeferredClustered);
        assert!(pick_lighting_path(&times(33.0, 1.0), true).1.contains("33.00×"));
        // Within the margin either way the probe cannot choose (auto renders the scene).
        for (fragment, close) in [(1.0, true), (1.25, true), (0.8, true), (1.3, false), (0.75, false), (33.0, false)] {
            assert_eq!(too_close_to_call(&times(fragment, 1.0)), close, "{fragment}");
        }
    }

    #[test]
    fn probe_lights_reach_every_pixel_of_the_floor() {
        let lights = probe_lights(1000);
        assert_eq!(lights.len(), 1000);
        for l in &lights {
            let [x, y, z, r] = l.position_radius;
            assert!((-20.0..=20.0).contains(&x) && (1.0..=8.0).contains(&y) && (-20.0..=20.0).contains(&z));
            // The farthest floor corner is under 60 m away.
            assert!(r > 60.0);
        }
        assert_ne!(lights[0].position_radius, lights[1].position_radius);
    }
}
