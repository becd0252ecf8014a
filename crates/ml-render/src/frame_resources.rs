//! What a frame slot's passes bind: one table of the frame's shared buffers and the scene's,
//! each under the name the shaders give its block (`FrameBlock`, `LightBuffer`, ...), and the
//! slot's render targets, the ones shaders sample under the names they give them. The frame
//! slot and the scene's GPU data each add their own entries; a pass asks by typed name
//! (`BufferName`) for what it hands on, and its shaders' bindings are looked up by the names
//! reflection gives — it knows nothing of who made them.

use crate::descriptors::Resource;
use crate::sync::{BufferName, DEPTH_PYRAMID, SURFACE_COLOURS, VISIBILITY_DEPTH};
use crate::targets::Targets;
use ml_vk::{vk, Image};
use std::cell::RefCell;

/// Frames recorded while the GPU works on the previous one (docs/DESIGN.md#frames-in-flight).
pub const FRAMES_IN_FLIGHT: usize = 2;

/// One frame slot's named buffers and its targets.
pub struct FrameResources<'a> {
    pub slot: usize,
    buffers: Vec<(BufferName, vk::Buffer)>,
    pub targets: &'a Targets,
    /// How shaders read the targets they sample (texelFetch: a sampler that filters nothing).
    fetch: vk::Sampler,
    /// The names found since `take_found`: what a pass's shaders bound from the table (the
    /// renderer checks them against the pass's declared uses).
    found: RefCell<Vec<&'static str>>,
}

impl<'a> FrameResources<'a> {
    /// Slot `slot`'s table: its targets' buffers (the depth pyramid, the compute raster's
    /// depth-and-id buffer, the surface colours) and images (sampled through `fetch`) and,
    /// added by `with`, everyone else's buffers (the slot's, the scene's, the passes' own).
    pub fn new(slot: usize, targets: &'a Targets, fetch: vk::Sampler) -> FrameResources<'a> {
        let buffers = vec![
            (DEPTH_PYRAMID, targets.depth_pyramid.raw),
            (VISIBILITY_DEPTH, targets.visibility_depth.raw),
            (SURFACE_COLOURS, targets.surface_colours.raw),
        ];
        FrameResources { slot, buffers, targets, fetch, found: RefCell::new(Vec::new()) }
    }

    /// The table with `named` buffers added (a name given twice is a bug: the first would
    /// shadow the second).
    pub fn with(mut self, named: &[(BufferName, vk::Buffer)]) -> FrameResources<'a> {
        for &(name, buffer) in named {
            debug_assert!(self.buffers.iter().all(|(n, _)| *n != name), "{} added twice", name.0);
            self.buffers.push((name, buffer));
        }
        self
    }

    /// What a shader binding called `name` binds, if the frame has it: a buffer by its
    /// block's name, or a target the shaders sample — `depth_image` and `opaque_depth` (the
    /// depth target), `visibility_image` (the hardware raster's ids), `hdr_image` (the linear
    /// HDR target, as the pass before left it to be read).
    pub fn resource(&self, name: &str) -> Option<Resource> {
        let t = self.targets;
        match name {
            "depth_image" | "opaque_depth" => self.sampled(&t.depth, vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL),
            "visibility_image" => self.sampled(&t.visibility, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
            "hdr_image" => self.sampled(&t.hdr, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL),
            _ => self.find(|n| n.0 == name).map(Resource::Buffer),
        }
    }

    /// `image` in `layout`, read through the frame's fetch sampler.
    pub fn sampled(&self, image: &Image, layout: vk::ImageLayout) -> Option<Resource> {
        Some(Resource::Image(vk::DescriptorImageInfo::default().sampler(self.fetch).image_view(image.view).image_layout(layout)))
    }

    /// The buffer called `name` itself (for passes that hand it on).
    pub fn raw_buffer(&self, name: BufferName) -> Option<vk::Buffer> {
        self.find(|n| n == name)
    }

    fn find(&self, is: impl Fn(BufferName) -> bool) -> Option<vk::Buffer> {
        let &(found, buffer) = self.buffers.iter().find(|(n, _)| is(*n))?;
        self.found.borrow_mut().push(found.0);
        Some(buffer)
    }

    /// The names looked up and found since the last call, each once.
    pub fn take_found(&self) -> Vec<&'static str> {
        let mut names = std::mem::take(&mut *self.found.borrow_mut());
        names.sort_unstable();
        names.dedup();
        names
    }
}
