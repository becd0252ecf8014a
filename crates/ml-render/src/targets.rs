//! Offscreen render targets of a frame slot: the colour image that is read back, the depth
//! buffer, the G-buffer and the HDR image of the deferred techniques. The raster passes make
//! their framebuffers over them.

use crate::antialiasing::Antialiasing;
use crate::technique::{Geometry, LightingStage, Raster, Technique};
use ml_vk::{vk, Buffer, Context, Image, VkError};

/// Size of the biggest image we agree to render, whatever the device allows: 16384² RGBA8 is
/// 1 GiB of colour alone, per frame in flight.
pub const MAX_DIMENSION: u32 = 16384;

/// Colour target format: the seed writes gamma-encoded values itself, so plain UNORM.
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
/// What the deferred lighting subpass writes: linear HDR colour, tone-mapped after.
pub const HDR_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// The G-buffer's images in attachment order (subpass 0's colour outputs, the lighting
/// subpass's inputs after depth, deferred-compute's bindings): the octahedral normal in two
/// floats (8 B; half floats would move the seed's sharp highlights by several 8-bit steps),
/// the object's index (4 B; its material is read from the object buffer at full precision),
/// the albedo factor sRGB-encoded with the ambient occlusion in alpha (4 B: a texture's dark
/// base colours keep the 8-bit steps they have in the texture; stored linear, a dark texel of
/// a model exposed several EV up moved the image by up to 6/255) — 16 B/pixel besides depth —
/// then, only in scenes whose objects have textures of their own (`gbuffer_images`), the
/// roughness and metallic factors (2 B) and the emissive factor (4 B, sRGB like its texture);
/// then, only where the PBR extensions vary per point (`GBufferKind::Lobes`), their texels in
/// one image (16 B; a subpass reads at most 8 input attachments on lavapipe): the clear coat's
/// octahedral normal (snorm 2×16), its strength and roughness, transmission and thickness,
/// the sheen's colour and roughness, the specular's colour and strength (unorm 4×8 each).
pub const GBUFFER: [GBufferImage; 6] = [
    GBufferImage {
        key: "normal", name: "g-buffer normal", format: vk::Format::R32G32_SFLOAT, bytes: 8, layout: "octahedral normal 2×f32"
    },
    GBufferImage { key: "object", name: "g-buffer object", format: vk::Format::R32_UINT, bytes: 4, layout: "object index u32" },
    GBufferImage {
        key: "albedo",
        name: "g-buffer albedo-occlusion",
        format: vk::Format::R8G8B8A8_SRGB,
        bytes: 4,
        layout: "albedo (sRGB)-occlusion RGBA8",
    },
    GBufferImage {
        key: "roughness_metallic",
        name: "g-buffer roughness-metallic",
        format: vk::Format::R8G8_UNORM,
        bytes: 2,
        layout: "roughness-metallic RG8",
    },
    GBufferImage { key: "emissive", name: "g-buffer emissive", format: vk::Format::R8G8B8A8_SRGB, bytes: 4, layout: "emissive RGBA8" },
    GBufferImage {
        key: "lobes",
        name: "g-buffer material lobes",
        format: vk::Format::R32G32B32A32_UINT,
        bytes: 16,
        layout: "extensions' texels RGBA32UI",
    },
];

/// Which of GBUFFER's images a scene's G-buffer has: the first three; five, where objects
/// have textures of their own; all, where their PBR extensions vary per point.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GBufferKind {
    Base,
    Material,
    Lobes,
}

pub struct GBufferImage {
    /// What the shaders call it (`normal_image`, `normal_input`: `normal`).
    pub key: &'static str,
    pub name: &'static str,
    pub format: vk::Format,
    /// Per pixel.
    pub bytes: u32,
    /// What it holds and how, in a few words (the table `render` prints).
    pub layout: &'static str,
}
/// The G-buffer images of a scene of `kind`. Images a scene does not use cost it even when
/// left unwritten (write mask 0): the seed scene's G-buffer pass took 1.85 ms instead of 1.55
/// on the H100 with the material and emissive images (measured).
pub fn gbuffer_images(kind: GBufferKind) -> &'static [GBufferImage] {
    &GBUFFER[..match kind {
        GBufferKind::Base => 3,
        GBufferKind::Material => 5,
        GBufferKind::Lobes => GBUFFER.len(),
    }]
}

/// What the raster pass writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Output {
    /// The shaded colour (forward techniques).
    Color,
    /// A G-buffer that a compute pass lights (deferred-compute).
    GBuffer,
    /// A G-buffer that the pass's second subpass lights into an HDR image (deferred,
    /// deferred-clustered); the G-buffer and depth live only inside the pass.
    Subpasses,
    /// A visibility buffer (an id per pixel) and depth, which a compute pass lights
    /// (visibility).
    Visibility,
}

impl Output {
    pub fn of(technique: Technique) -> Output {
        match (technique.geometry(), technique.lighting_stage()) {
            (Geometry::Meshlets, _) => Output::Visibility,
            (Geometry::Meshes, LightingStage::Forward) => Output::Color,
            (Geometry::Meshes, LightingStage::Subpass) => Output::Subpasses,
            (Geometry::Meshes, LightingStage::Compute) => Output::GBuffer,
        }
    }

    /// Colour attachments the meshes are drawn into (subpass 0), given the G-buffer's images.
    pub fn colour_attachments(self, gbuffer: &[GBufferImage]) -> usize {
        match self {
            Output::Color | Output::Visibility => 1,
            Output::GBuffer | Output::Subpasses => gbuffer.len(),
        }
    }
}

/// Bytes per pixel of a scene's G-buffer, depth excluded (the figure `render` prints).
pub fn gbuffer_bytes_per_pixel(kind: GBufferKind) -> u32 {
    gbuffer_images(kind).iter().map(|g| g.bytes).sum()
}

/// The first depth format the device can render to (and, for a G-buffer, sample).
pub fn depth_format(ctx: &Context, output: Output) -> Result<vk::Format, VkError> {
    let mut needs = vk::FormatFeatureFlags::DEPTH_STENCIL_ATTACHMENT;
    if output != Output::Color {
        // Read by the lighting pass (sampled, or loaded as an input attachment).
        needs |= vk::FormatFeatureFlags::SAMPLED_IMAGE;
    }
    [vk::Format::D32_SFLOAT, vk::Format::X8_D24_UNORM_PACK32]
        .into_iter()
        .find(|&f| ctx.format_supports(f, needs))
        .ok_or_else(|| VkError::Unsupported { device: ctx.info.name.clone(), what: format!("a depth format with {needs:?}") })
}

/// The multisampled attachments a raster pass draws into with anti-aliasing (name, format,
/// usage): the forward pass's colour and depth, the G-buffer's images (all five: a scene's may
/// have them) and depth (deferred and deferred-compute), or the hardware visibility raster's
/// ids and depth. What `Targets`
/// makes of them, and what the settings check against the device's sample counts before.
pub fn multisampled_images(
    output: Output,
    raster: Raster,
    depth_format: vk::Format,
) -> Vec<(&'static str, vk::Format, vk::ImageUsageFlags)> {
    use vk::ImageUsageFlags as U;
    let inside = U::TRANSIENT_ATTACHMENT;
    let depth = ("depth", depth_format, U::DEPTH_STENCIL_ATTACHMENT | inside);
    match output {
        // The hardware visibility raster's images, which a compute pass gathers into the
        // 64-bit buffer (the compute rasters draw into that buffer alone).
        Output::Visibility if raster == Raster::Hardware => vec![
            ("visibility buffer", VISIBILITY_FORMAT, U::COLOR_ATTACHMENT | U::SAMPLED),
            ("depth", depth_format, U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED),
        ],
        Output::Color => vec![("colour", HDR_FORMAT, U::COLOR_ATTACHMENT | inside), depth],
        Output::Subpasses => GBUFFER
            .iter()
            .map(|g| (g.name, g.format, U::COLOR_ATTACHMENT | U::INPUT_ATTACHMENT | inside))
            .chain([(depth.0, depth.1, depth.2 | U::INPUT_ATTACHMENT)])
            .collect(),
        // deferred-compute's, which its compute lighting reads.
        Output::GBuffer => GBUFFER
            .iter()
            .map(|g| (g.name, g.format, U::COLOR_ATTACHMENT | U::SAMPLED))
            .chain([(depth.0, depth.1, U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED)])
            .collect(),
        _ => Vec::new(),
    }
}

pub struct Targets {
    /// The image that is read back (a colour attachment, or a storage image the lighting
    /// compute pass or the tone map writes).
    pub color: Image,
    pub depth: Image,
    /// Deferred techniques: the scene's G-buffer images (`gbuffer_images`; empty otherwise).
    pub gbuffer: Vec<Image>,
    /// deferred, deferred-clustered: the lighting subpass's HDR output; with transparent
    /// layers, the forward or compute lighting pass's linear output (null otherwise).
    pub hdr: Image,
    /// visibility: the visibility buffer (null otherwise).
    pub visibility: Image,
    /// visibility: the depth pyramid of the late culling phase, level after level (null
    /// otherwise).
    pub depth_pyramid: Buffer,
    /// Forward techniques with anti-aliasing: the multisampled colour the meshes are drawn
    /// into (the display's linear light), resolved into `hdr` (null otherwise).
    pub colour_samples: Image,
    /// visibility with the compute or hybrid raster: 64 bits per sample (`Antialiasing`), depth
    /// and id, which its passes write by atomic min and the depth pyramid and the lighting read
    /// (`depth` and `visibility` are null then); with the hardware raster and anti-aliasing,
    /// its multisampled images gathered (null otherwise).
    pub visibility_depth: Buffer,
    /// visibility with anti-aliasing and transparent layers: each opaque surface's linear
    /// colour at its first sample, in `visibility_depth`'s layout (8 bytes a sample), for the
    /// layers' blend (null otherwise).
    pub surface_colours: Buffer,
}

/// Format of the visibility buffer: the 32-bit id (meshlets.rs).
pub const VISIBILITY_FORMAT: vk::Format = vk::Format::R32_UINT;

/// The depth pyramid's level 0 for an image of `extent`: its size rounded up to powers of
/// two and halved (every level then halves exactly), and the levels down to 1×1.
/// (depth_pyramid.glsl lays it out the same way).
pub fn depth_pyramid_shape(extent: vk::Extent2D) -> (vk::Extent2D, u32) {
    let half = |n: u32| (n.max(2).next_power_of_two() / 2).max(1);
    let base = vk::Extent2D { width: half(extent.width), height: half(extent.height) };
    (base, base.width.max(base.height).ilog2() + 1)
}

/// Size of level `level` of the depth pyramid of an image of `extent`.
pub fn depth_pyramid_level(extent: vk::Extent2D, level: u32) -> vk::Extent2D {
    let (base, _) = depth_pyramid_shape(extent);
    vk::Extent2D { width: (base.width >> level).max(1), height: (base.height >> level).max(1) }
}

/// Depths of every level of the pyramid together.
pub fn depth_pyramid_len(extent: vk::Extent2D) -> u64 {
    let (_, levels) = depth_pyramid_shape(extent);
    (0..levels).map(|l| depth_pyramid_level(extent, l)).map(|e| e.width as u64 * e.height as u64).sum()
}

impl Targets {
    /// The target called `name` and its aspect, for the barriers between passes (`sync`):
    /// the colour target.
    pub fn named_image(&self, name: crate::sync::ImageName) -> Option<(vk::Image, vk::ImageAspectFlags)> {
        match name {
            crate::sync::COLOUR_TARGET => Some((self.color.raw, vk::ImageAspectFlags::COLOR)),
            crate::sync::HDR_TARGET => Some((self.hdr.raw, vk::ImageAspectFlags::COLOR)),
            _ => None,
        }
    }

    /// `layers`: transparent layers are blended over the opaque pass (their build samples the
    /// opaque depth; the opaque pass writes linear HDR).
    pub fn new(
        ctx: &Context,
        extent: vk::Extent2D,
        depth_format: vk::Format,
        (output, gbuffer): (Output, &[GBufferImage]),
        (raster, layers, antialiasing): (Raster, bool, Antialiasing),
    ) -> Result<Targets, VkError> {
        let t = Targets {
            color: Image::null(),
            depth: Image::null(),
            gbuffer: Vec::new(),
            hdr: Image::null(),
            visibility: Image::null(),
            depth_pyramid: Buffer::null(),
            visibility_depth: Buffer::null(),
            surface_colours: Buffer::null(),
            colour_samples: Image::null(),
        };
        ml_vk::build(ctx, t, |t| t.create(ctx, extent, depth_format, (output, gbuffer), (raster, layers, antialiasing)))
    }

    fn create(
        &mut self,
        ctx: &Context,
        extent: vk::Extent2D,
        depth_format: vk::Format,
        (output, gbuffer): (Output, &[GBufferImage]),
        (raster, layers, antialiasing): (Raster, bool, Antialiasing),
    ) -> Result<(), VkError> {
        use vk::ImageUsageFlags as U;
        let colour = vk::ImageAspectFlags::COLOR;
        // The subpass G-buffer never leaves the render pass: TRANSIENT lets a tiler keep it in
        // tile memory (the device still backs it with ordinary memory where it has no lazy kind).
        let inside_pass = U::INPUT_ATTACHMENT | U::TRANSIENT_ATTACHMENT;
        // With transparent layers, their build samples the opaque depth.
        let layer_depth = if layers { U::SAMPLED } else { U::empty() };
        let (color_usage, depth_usage, gbuffer_usage) = match output {
            // STORAGE: the shadow-map debug view paints over it with a compute pass.
            Output::Color => (U::COLOR_ATTACHMENT | U::TRANSFER_SRC | U::STORAGE, U::DEPTH_STENCIL_ATTACHMENT | layer_depth, U::empty()),
            Output::GBuffer => (U::STORAGE | U::TRANSFER_SRC, U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED, U::COLOR_ATTACHMENT | U::SAMPLED),
            Output::Subpasses => {
                let depth = if layers { U::INPUT_ATTACHMENT | U::SAMPLED } else { inside_pass };
                (U::STORAGE | U::TRANSFER_SRC, U::DEPTH_STENCIL_ATTACHMENT | depth, U::COLOR_ATTACHMENT | inside_pass)
            }
            Output::Visibility => (U::STORAGE | U::TRANSFER_SRC, U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED, U::empty()),
        };
        // The compute raster keeps depth and ids in one buffer: no images of them. The
        // hardware raster's samples are gathered into that buffer too.
        let compute_raster = output == Output::Visibility && raster != Raster::Hardware;
        let keeps_buffer = output == Output::Visibility && raster.fills_buffer(antialiasing);
        // Anti-aliasing's multisampled attachments (Antialiasing::Off: one sample). The forward
        // pass's and the deferred subpasses' never leave the render pass (render_pass.rs
        // describe); deferred-compute's G-buffer and the hardware visibility raster's images
        // are read in compute.
        let samples = antialiasing.sample_count();
        let multisampled = antialiasing != Antialiasing::Off && matches!(output, Output::Color | Output::Subpasses);
        let inside_only = if multisampled { U::TRANSIENT_ATTACHMENT } else { U::empty() };
        let (depth_usage, gbuffer_usage) = (depth_usage | inside_only, gbuffer_usage | inside_only);
        self.color = Image::new_2d(ctx, "colour target", extent, COLOR_FORMAT, color_usage, colour)?;
        if !compute_raster {
            let depth = vk::ImageAspectFlags::DEPTH;
            self.depth = Image::new_2d_samples(ctx, "depth target", (extent, samples), depth_format, depth_usage, depth)?;
        }
        if matches!(output, Output::GBuffer | Output::Subpasses) {
            for g in gbuffer {
                self.gbuffer.push(Image::new_2d_samples(ctx, g.name, (extent, samples), g.format, gbuffer_usage, colour)?);
            }
        }
        if multisampled && output == Output::Color {
            let usage = U::COLOR_ATTACHMENT | inside_only;
            self.colour_samples = Image::new_2d_samples(ctx, "colour samples", (extent, samples), HDR_FORMAT, usage, colour)?;
        }
        if output == Output::Subpasses || (output == Output::Color && (layers || multisampled)) {
            self.hdr = Image::new_2d(ctx, "hdr target", extent, HDR_FORMAT, U::COLOR_ATTACHMENT | U::SAMPLED, colour)?;
        } else if layers && !(output == Output::Visibility && antialiasing != Antialiasing::Off) {
            // The compute lighting's linear output, which the transparent resolve reads
            // (anti-aliased, the visibility lighting keeps its surfaces' colours instead).
            self.hdr = Image::new_2d(ctx, "hdr target", extent, HDR_FORMAT, U::STORAGE | U::SAMPLED, colour)?;
        }
        if output == Output::Visibility {
            if !compute_raster {
                let usage = U::COLOR_ATTACHMENT | U::SAMPLED;
                self.visibility = Image::new_2d_samples(ctx, "visibility buffer", (extent, samples), VISIBILITY_FORMAT, usage, colour)?;
            }
            let bytes = depth_pyramid_len(extent) * 4;
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
            self.depth_pyramid = Buffer::new(ctx, "depth pyramid", bytes, usage, gpu_allocator::MemoryLocation::GpuOnly)?;
        }
        if keeps_buffer {
            let bytes = antialiasing.buffer_bytes(extent.width, extent.height);
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
            self.visibility_depth = Buffer::new(ctx, "visibility-depth buffer", bytes, usage, gpu_allocator::MemoryLocation::GpuOnly)?;
            if layers && antialiasing != Antialiasing::Off {
                let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
                self.surface_colours = Buffer::new(ctx, "surface colours", bytes, usage, gpu_allocator::MemoryLocation::GpuOnly)?;
            }
        }
        Ok(())
    }

    /// Bytes of the multisampled attachments (anti-aliasing's samples: depth, and the forward
    /// pass's colour, the G-buffer or the hardware visibility raster's ids) and of the surface
    /// colours kept per sample for the transparent layers.
    pub fn multisampled_bytes(&self) -> u64 {
        let ids = self.colour_samples.bytes + self.visibility.bytes;
        self.depth.bytes + ids + self.gbuffer.iter().map(|g| g.bytes).sum::<u64>() + self.surface_colours.size
    }

    /// The G-buffer image the shaders call `key` (`normal`, `object`, `albedo`, …), where the
    /// scene's G-buffer has it.
    pub fn gbuffer_image(&self, key: &str) -> Option<&Image> {
        GBUFFER.iter().position(|g| g.key == key).and_then(|i| self.gbuffer.get(i))
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.color.destroy(ctx);
        self.depth.destroy(ctx);
        for image in &mut self.gbuffer {
            image.destroy(ctx);
        }
        self.hdr.destroy(ctx);
        self.visibility.destroy(ctx);
        self.depth_pyramid.destroy(ctx);
        self.visibility_depth.destroy(ctx);
        self.surface_colours.destroy(ctx);
        self.colour_samples.destroy(ctx);
    }
}

impl ml_vk::Release for Targets {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
