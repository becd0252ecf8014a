//! The raster pass's VkRenderPass as plain data first (tests inspect it: the deferred technique is two subpasses with input attachments), then created from that data.
//!
//! Output::Color and Output::GBuffer: one subpass. Output::Subpasses (docs/DESIGN.md#deferred-shading-in-one-render-pass): the G-buffer
//! images (normal, object index, albedo, and in scenes with object textures roughness-metallic
//! and emissive), then depth — written by subpass 0, read by subpass 1 as input attachments,
//! never stored — and last HDR colour, written by subpass 1 and read by the tone-map compute
//! pass.

use crate::targets::{GBufferImage, Output, COLOR_FORMAT, HDR_FORMAT, VISIBILITY_FORMAT};
use ml_vk::{vk, Context, VkError, VkResultExt};

/// One subpass: which attachments it writes and reads.
#[derive(Clone, Debug, Default)]
pub struct Subpass {
    pub colour: Vec<vk::AttachmentReference>,
    pub depth: Option<vk::AttachmentReference>,
    /// Read with subpassLoad, in input_attachment_index order.
    pub inputs: Vec<vk::AttachmentReference>,
    /// Where each multisampled colour attachment is resolved at the subpass's end (none, or
    /// one per colour attachment).
    pub resolve: Vec<vk::AttachmentReference>,
}

#[derive(Clone, Debug)]
pub struct RenderPassDesc {
    pub attachments: Vec<vk::AttachmentDescription>,
    pub subpasses: Vec<Subpass>,
    pub dependencies: Vec<vk::SubpassDependency>,
}

fn attachment(format: vk::Format, store: bool, final_layout: vk::ImageLayout) -> vk::AttachmentDescription {
    vk::AttachmentDescription::default()
        .format(format)
        .samples(vk::SampleCountFlags::TYPE_1)
        .load_op(vk::AttachmentLoadOp::CLEAR)
        .store_op(if store { vk::AttachmentStoreOp::STORE } else { vk::AttachmentStoreOp::DONT_CARE })
        .stencil_load_op(vk::AttachmentLoadOp::DONT_CARE)
        .stencil_store_op(vk::AttachmentStoreOp::DONT_CARE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
        .final_layout(final_layout)
}

fn reference(attachment: u32, layout: vk::ImageLayout) -> vk::AttachmentReference {
    vk::AttachmentReference { attachment, layout }
}

const COLOUR_OUT: vk::PipelineStageFlags = vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT;
/// The transparent layers' build samples the opaque depth in its fragment shader.
const FRAGMENT: vk::PipelineStageFlags = vk::PipelineStageFlags::FRAGMENT_SHADER;
const FRAGMENT_TESTS: vk::PipelineStageFlags = vk::PipelineStageFlags::from_raw(
    vk::PipelineStageFlags::EARLY_FRAGMENT_TESTS.as_raw() | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS.as_raw(),
);
const ATTACHMENT_WRITES: vk::AccessFlags =
    vk::AccessFlags::from_raw(vk::AccessFlags::COLOR_ATTACHMENT_WRITE.as_raw() | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw());

fn dependency(
    src: (u32, vk::PipelineStageFlags, vk::AccessFlags),
    dst: (u32, vk::PipelineStageFlags, vk::AccessFlags),
) -> vk::SubpassDependency {
    vk::SubpassDependency::default()
        .src_subpass(src.0)
        .src_stage_mask(src.1)
        .src_access_mask(src.2)
        .dst_subpass(dst.0)
        .dst_stage_mask(dst.1)
        .dst_access_mask(dst.2)
}

/// The render pass the raster pass uses for `output`, with `gbuffer`'s images (targets.rs
/// gbuffer_images) where it writes a G-buffer. With transparent `layers`, whose build
/// samples the opaque depth after the pass, depth is stored and the forward pass writes
/// linear HDR for their resolve. With `samples` above one (anti-aliasing), the meshes are
/// drawn into multisampled attachments: the forward pass's colour, the display's linear light
/// in HDR_FORMAT, is resolved into the HDR target (the mean of the samples: a box filter in
/// the display's linear light), which the tone map encodes; the deferred lighting subpass reads
/// the multisampled G-buffer and depth and writes the HDR target once per pixel.
pub fn describe(
    depth_format: vk::Format,
    output: Output,
    gbuffer: &[GBufferImage],
    (layers, samples): (bool, vk::SampleCountFlags),
) -> RenderPassDesc {
    let mut desc = match output {
        Output::Color if samples != vk::SampleCountFlags::TYPE_1 => return multisampled_forward(depth_format, samples),
        Output::Color | Output::GBuffer => one_subpass(depth_format, output, gbuffer, layers),
        Output::Subpasses => two_subpasses(depth_format, gbuffer, layers),
        Output::Visibility => visibility(depth_format, true, samples),
    };
    // Subpass 0's attachments (the G-buffer and depth) take the samples; the lighting
    // subpass's HDR output (the last attachment) keeps one. deferred-compute's G-buffer and
    // depth are read sample by sample by its compute lighting.
    let multisampled = match output {
        Output::Subpasses => desc.attachments.len() - 1,
        Output::GBuffer => desc.attachments.len(),
        _ => 0,
    };
    for a in &mut desc.attachments[..multisampled] {
        a.samples = samples;
    }
    desc
}

/// The forward pass with anti-aliasing: the multisampled colour (the display's linear light)
/// and depth never leave the pass; the colour is resolved into the single-sampled HDR target,
/// which the tone map reads.
fn multisampled_forward(depth_format: vk::Format, samples: vk::SampleCountFlags) -> RenderPassDesc {
    let colour = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
    let depth = vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
    let attachments = vec![
        attachment(HDR_FORMAT, false, colour).samples(samples),
        attachment(depth_format, false, depth).samples(samples),
        // Every pixel is written by the resolve: nothing to clear.
        attachment(HDR_FORMAT, true, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL).load_op(vk::AttachmentLoadOp::DONT_CARE),
    ];
    let subpass = Subpass {
        colour: vec![reference(0, colour)],
        depth: Some(reference(1, depth)),
        inputs: Vec::new(),
        resolve: vec![reference(2, colour)],
    };
    let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
    let dependencies = vec![
        // The earlier frame's tone map read the HDR target this pass resolves into again.
        dependency(
            (vk::SUBPASS_EXTERNAL, COLOUR_OUT | FRAGMENT_TESTS | compute, ATTACHMENT_WRITES),
            (0, COLOUR_OUT | FRAGMENT_TESTS, ATTACHMENT_WRITES | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ),
        ),
        // The resolve (a colour attachment write) before the tone map reads it.
        dependency((0, COLOUR_OUT, vk::AccessFlags::COLOR_ATTACHMENT_WRITE), (vk::SUBPASS_EXTERNAL, compute, vk::AccessFlags::SHADER_READ)),
    ];
    RenderPassDesc { attachments, subpasses: vec![subpass], dependencies }
}

/// The transparent layers' build: no attachments — its fragments test the opaque depth and
/// append to the lists themselves — between the opaque raster (its depth, by the raster's
/// own outgoing dependency; the lists' clearing, by the build's barrier) and the passes that
/// blend the lists, ordered by their declared uses.
/// The visibility raster's pass: the visibility buffer and depth, cleared by the early phase
/// (`first`), kept by the late one. Between them the depth pyramid samples depth; after the
/// late phase the lighting pass samples both. With `samples` above one (anti-aliasing) a
/// compute pass gathers both into the 64-bit buffer after each phase: the ids leave each
/// phase ready to be read.
pub fn visibility(depth_format: vk::Format, first: bool, samples: vk::SampleCountFlags) -> RenderPassDesc {
    let colour = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
    let depth_read_only = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
    let kept = |a: vk::AttachmentDescription, before: vk::ImageLayout| {
        if first {
            a
        } else {
            a.load_op(vk::AttachmentLoadOp::LOAD).initial_layout(before)
        }
    };
    let gathered = samples != vk::SampleCountFlags::TYPE_1;
    let read = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
    let ids_after = if first && !gathered { colour } else { read };
    let ids_before = if gathered { read } else { colour };
    let attachments = vec![
        kept(attachment(VISIBILITY_FORMAT, true, ids_after).samples(samples), ids_before),
        kept(attachment(depth_format, true, depth_read_only).samples(samples), depth_read_only),
    ];
    let subpass = Subpass {
        colour: vec![reference(0, colour)],
        depth: Some(reference(1, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)),
        inputs: Vec::new(),
        resolve: Vec::new(),
    };
    let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
    // The draws and their count come from the culling pass (compute writes); the vertex
    // shader reads the scene's buffers.
    let draws = vk::PipelineStageFlags::DRAW_INDIRECT | vk::PipelineStageFlags::VERTEX_SHADER;
    let draws_read = vk::AccessFlags::INDIRECT_COMMAND_READ | vk::AccessFlags::SHADER_READ;
    let dependencies = vec![
        // The earlier frame's (or, late, the pyramid's) readers of the attachments, the culling's
        // writes of the draws.
        dependency(
            (vk::SUBPASS_EXTERNAL, COLOUR_OUT | FRAGMENT_TESTS | compute | FRAGMENT, ATTACHMENT_WRITES | vk::AccessFlags::SHADER_WRITE),
            (
                0,
                COLOUR_OUT | FRAGMENT_TESTS | draws,
                ATTACHMENT_WRITES | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ | vk::AccessFlags::COLOR_ATTACHMENT_READ | draws_read,
            ),
        ),
        // The pyramid (depth) and the lighting (both) read them in compute; the late phase
        // loads them again.
        dependency(
            (0, COLOUR_OUT | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS, ATTACHMENT_WRITES),
            (vk::SUBPASS_EXTERNAL, compute | COLOUR_OUT | FRAGMENT_TESTS | FRAGMENT, vk::AccessFlags::SHADER_READ | ATTACHMENT_WRITES),
        ),
    ];
    RenderPassDesc { attachments, subpasses: vec![subpass], dependencies }
}

/// The hybrid raster's hardware half (visibility_atomic.frag): no attachments — its
/// fragments write the 64-bit visibility-depth buffer by atomic min — one subpass between the
/// culling's writes (the draw, the compute raster's pixels) and the compute passes after it
/// (the depth pyramid, the late culling's raster, the lighting).
pub fn visibility_atomic() -> RenderPassDesc {
    let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
    let fragment = vk::PipelineStageFlags::FRAGMENT_SHADER;
    let draws =
        vk::PipelineStageFlags::DRAW_INDIRECT | vk::PipelineStageFlags::VERTEX_INPUT | vk::PipelineStageFlags::VERTEX_SHADER | fragment;
    let rw = vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE;
    let dependencies = vec![
        dependency(
            (vk::SUBPASS_EXTERNAL, compute, vk::AccessFlags::SHADER_WRITE),
            (0, draws, vk::AccessFlags::INDIRECT_COMMAND_READ | vk::AccessFlags::INDEX_READ | rw),
        ),
        dependency((0, fragment, vk::AccessFlags::SHADER_WRITE), (vk::SUBPASS_EXTERNAL, compute, rw)),
    ];
    RenderPassDesc { attachments: Vec::new(), subpasses: vec![Subpass::default()], dependencies }
}

fn one_subpass(depth_format: vk::Format, output: Output, gbuffer: &[GBufferImage], layers: bool) -> RenderPassDesc {
    let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
    let depth_read_only = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
    let attachments = match output {
        // Linear HDR and depth for the transparent layers' build and resolve.
        Output::Color if layers => vec![attachment(HDR_FORMAT, true, read_only), attachment(depth_format, true, depth_read_only)],
        // The colour result is copied out; depth is not needed afterwards.
        Output::Color => vec![
            attachment(COLOR_FORMAT, true, vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
            attachment(depth_format, false, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
        ],
        // Everything is read by the lighting compute pass.
        _ => gbuffer
            .iter()
            .map(|g| attachment(g.format, true, read_only))
            .chain([attachment(depth_format, true, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL)])
            .collect(),
    };
    let colour_count = output.colour_attachments(gbuffer) as u32;
    let subpass = Subpass {
        colour: (0..colour_count).map(|a| reference(a, vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL)).collect(),
        depth: Some(reference(colour_count, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)),
        inputs: Vec::new(),
        resolve: Vec::new(),
    };
    // Who uses the attachments after the pass: the read-back copy, or the lighting compute pass
    // (and the transparent layers' build, in fragment shaders).
    let after = match output {
        Output::Color if !layers => (vk::PipelineStageFlags::TRANSFER, vk::AccessFlags::TRANSFER_READ),
        _ => (vk::PipelineStageFlags::COMPUTE_SHADER | FRAGMENT, vk::AccessFlags::SHADER_READ),
    };
    let dependencies = vec![
        // The targets are reused every other frame: wait for the earlier frame's attachment
        // writes and its readers before clearing them again.
        dependency(
            (vk::SUBPASS_EXTERNAL, COLOUR_OUT | FRAGMENT_TESTS | after.0, ATTACHMENT_WRITES),
            (0, COLOUR_OUT | FRAGMENT_TESTS, ATTACHMENT_WRITES | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ),
        ),
        dependency(
            (0, COLOUR_OUT | vk::PipelineStageFlags::LATE_FRAGMENT_TESTS, ATTACHMENT_WRITES),
            (vk::SUBPASS_EXTERNAL, after.0, after.1),
        ),
    ];
    RenderPassDesc { attachments, subpasses: vec![subpass], dependencies }
}

fn two_subpasses(depth_format: vk::Format, gbuffer: &[GBufferImage], layers: bool) -> RenderPassDesc {
    let read_only = vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL;
    let depth_read_only = vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL;
    let colour = vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL;
    let g = gbuffer.len() as u32;
    let (depth, hdr) = (g, g + 1);
    let attachments: Vec<vk::AttachmentDescription> = gbuffer
        .iter()
        .map(|image| attachment(image.format, false, read_only))
        .chain([attachment(depth_format, layers, depth_read_only), attachment(HDR_FORMAT, true, read_only)])
        .collect();
    let subpasses = vec![
        Subpass {
            colour: (0..g).map(|a| reference(a, colour)).collect(),
            depth: Some(reference(depth, vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL)),
            inputs: Vec::new(),
            resolve: Vec::new(),
        },
        // input_attachment_index 0 (depth), then 1… (the G-buffer) in deferred_frag.glsl.
        Subpass {
            colour: vec![reference(hdr, colour)],
            depth: None,
            inputs: [reference(depth, depth_read_only)].into_iter().chain((0..g).map(|a| reference(a, read_only))).collect(),
            resolve: Vec::new(),
        },
    ];
    let fragment = vk::PipelineStageFlags::FRAGMENT_SHADER;
    let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
    let colour_write = vk::AccessFlags::COLOR_ATTACHMENT_WRITE;
    let external = vk::SUBPASS_EXTERNAL;
    let mut dependencies = vec![
        // The targets are reused every other frame: the G-buffer was last written by that
        // frame's subpass 0 and read by its subpass 1 (and depth, with transparent layers, by
        // their build's fragment or compute shaders) ...
        dependency(
            (external, COLOUR_OUT | FRAGMENT_TESTS | fragment | compute, ATTACHMENT_WRITES),
            (0, COLOUR_OUT | FRAGMENT_TESTS, ATTACHMENT_WRITES | vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_READ),
        ),
        // ... and the HDR image written by its subpass 1 and read by its tone map.
        dependency((external, COLOUR_OUT | compute, colour_write), (1, COLOUR_OUT, colour_write)),
        // The subpass dependency: G-buffer writes before the lighting subpass reads them, per
        // pixel (BY_REGION: a tiler never leaves the tile).
        dependency((0, COLOUR_OUT | FRAGMENT_TESTS, ATTACHMENT_WRITES), (1, fragment, vk::AccessFlags::INPUT_ATTACHMENT_READ))
            .dependency_flags(vk::DependencyFlags::BY_REGION),
        // HDR writes before the tone map reads them.
        dependency((1, COLOUR_OUT, colour_write), (external, compute, vk::AccessFlags::SHADER_READ)),
    ];
    if layers {
        // Depth before the transparent layers' build samples it: written by subpass 0, stored
        // at the end of subpass 1 (its last user: the store is a depth write there).
        let tests = vk::PipelineStageFlags::LATE_FRAGMENT_TESTS;
        let depth_write = vk::AccessFlags::DEPTH_STENCIL_ATTACHMENT_WRITE;
        for subpass in [0, 1] {
            let build = FRAGMENT | vk::PipelineStageFlags::COMPUTE_SHADER;
            dependencies.push(dependency((subpass, tests, depth_write), (external, build, vk::AccessFlags::SHADER_READ)));
        }
    }
    RenderPassDesc { attachments, subpasses, dependencies }
}

/// Replace `framebuffer` (destroyed; null while a new one is made, so a failure leaves
/// nothing to destroy twice) by one of `render_pass` over `views`, `extent` large. Only while
/// no frame that uses it is in flight.
pub fn replace_framebuffer(
    ctx: &Context,
    framebuffer: &mut vk::Framebuffer,
    render_pass: vk::RenderPass,
    views: &[vk::ImageView],
    extent: vk::Extent2D,
) -> Result<(), VkError> {
    let info = vk::FramebufferCreateInfo::default()
        .render_pass(render_pass)
        .attachments(views)
        .width(extent.width)
        .height(extent.height)
        .layers(1);
    // SAFETY: the caller's views and render pass are compatible and alive; the old framebuffer
    // is not in use.
    unsafe {
        ctx.device.destroy_framebuffer(*framebuffer, None);
        *framebuffer = vk::Framebuffer::null();
        *framebuffer = ctx.device.create_framebuffer(&info, None).ctx("vkCreateFramebuffer")?;
    }
    Ok(())
}

impl RenderPassDesc {
    pub fn create(&self, ctx: &Context) -> Result<vk::RenderPass, VkError> {
        let subpasses: Vec<vk::SubpassDescription> = self
            .subpasses
            .iter()
            .map(|s| {
                let d = vk::SubpassDescription::default()
                    .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
                    .color_attachments(&s.colour)
                    .input_attachments(&s.inputs);
                let d = if s.resolve.is_empty() { d } else { d.resolve_attachments(&s.resolve) };
                match &s.depth {
                    Some(depth) => d.depth_stencil_attachment(depth),
                    None => d,
                }
            })
            .collect();
        let info =
            vk::RenderPassCreateInfo::default().attachments(&self.attachments).subpasses(&subpasses).dependencies(&self.dependencies);
        ml_vk::shader::render_pass(ctx, &info)
    }
}
