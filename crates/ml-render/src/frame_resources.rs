//! What a frame slot's passes bind: one table of the frame's shared buffers and the scene's,
//! each under the name the shaders give its block (`FrameBlock`, `LightBuffer`, ...), and the
//! slot's render targets. The frame slot and the scene's GPU data each add their own entries;
//! a pass looks up the names its shaders declare and knows nothing of who made them.

use crate::descriptors::Resource;
use crate::sync::{DEPTH_PYRAMID, SURFACE_COLOURS, VISIBILITY_DEPTH};
use crate::targets::Targets;
use ml_vk::vk;
use std::cell::RefCell;

/// Frames recorded while the GPU works on the previous one (docs/DESIGN.md#frames-in-flight).
pub const FRAMES_IN_FLIGHT: usize = 2;

/// One frame slot's named buffers and its targets.
pub struct FrameResources<'a> {
    pub slot: usize,
    buffers: Vec<(&'static str, vk::Buffer)>,
    pub targets: &'a Targets,
    /// The names found since `take_found`: what a pass's shaders bound from the table (the
    /// renderer checks them against the pass's declared uses).
    found: RefCell<Vec<&'static str>>,
}

impl<'a> FrameResources<'a> {
    /// Slot `slot`'s table: its targets' buffers (the depth pyramid, the compute raster's
    /// depth-and-id buffer, the surface colours) and, added by `with`, everyone else's (the slot's, the scene's,
    /// the passes' own).
    pub fn new(slot: usize, targets: &'a Targets) -> FrameResources<'a> {
        let buffers = vec![
            (DEPTH_PYRAMID, targets.depth_pyramid.raw),
            (VISIBILITY_DEPTH, targets.visibility_depth.raw),
            (SURFACE_COLOURS, targets.surface_colours.raw),
        ];
        FrameResources { slot, buffers, targets, found: RefCell::new(Vec::new()) }
    }

    /// The table with `named` buffers added (a name given twice is a bug: the first would
    /// shadow the second).
    pub fn with(mut self, named: &[(&'static str, vk::Buffer)]) -> FrameResources<'a> {
        for &(name, buffer) in named {
            debug_assert!(self.buffers.iter().all(|(n, _)| *n != name), "{name} added twice");
            self.buffers.push((name, buffer));
        }
        self
    }

    /// The buffer a shader block called `name` binds, if the frame has one.
    pub fn buffer(&self, name: &str) -> Option<Resource> {
        self.raw_buffer(name).map(Resource::Buffer)
    }

    /// The buffer called `name` itself (for passes that hand it on).
    pub fn raw_buffer(&self, name: &str) -> Option<vk::Buffer> {
        let &(found, buffer) = self.buffers.iter().find(|(n, _)| *n == name)?;
        self.found.borrow_mut().push(found);
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
