//! The transparent layers' buffers of a frame slot (layers.glsl), owned by the build pass and
//! named to the frame's table of resources, where the resolve finds them.

use crate::sync::BufferName;
use ml_vk::{vk, Buffer, Context, VkError};

/// The transparent layers' per-frame buffers, by their shader names: heads, nodes, counters
/// (transparency/layers.glsl).
pub const LAYER_BUFFERS: [BufferName; 3] =
    [BufferName("TransparentHeadBuffer"), BufferName("TransparentNodeBuffer"), BufferName("TransparentCountBuffer")];

/// Bytes of a transparent layer's node: two uvec4, three where the scene's PBR extensions
/// vary per point (`LOBE_TEXTURES`: their texels, transparency/layers.glsl).
pub fn node_bytes(lobe_textures: bool) -> u64 {
    if lobe_textures {
        48
    } else {
        32
    }
}

/// A frame slot's transparent layers: heads, node pool, counters (host-visible: the build pass
/// reads them when the frame is done). The build owns them; the frame's table names them.
pub struct LayerBuffers {
    pub heads: Buffer,
    pub nodes: Buffer,
    pub counts: Buffer,
    /// Bytes a node (`node_bytes`).
    pub node_bytes: u64,
}

impl LayerBuffers {
    /// `nodes`: the pool's size, of `node_bytes` each.
    pub fn new(ctx: &Context, extent: vk::Extent2D, (nodes, node_bytes): (u64, u64)) -> Result<LayerBuffers, VkError> {
        let b = LayerBuffers { heads: Buffer::null(), nodes: Buffer::null(), counts: Buffer::null(), node_bytes };
        ml_vk::build(ctx, b, |b| {
            use gpu_allocator::MemoryLocation as M;
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
            let (heads, nodes) = (extent.width as u64 * extent.height as u64 * 4, nodes * node_bytes);
            b.heads = Buffer::new(ctx, "transparent heads", heads, usage, M::GpuOnly)?;
            b.nodes = Buffer::new(ctx, "transparent nodes", nodes, usage, M::GpuOnly)?;
            b.counts = Buffer::new(ctx, "transparent counters", 16, usage, M::GpuToCpu)?;
            Ok(())
        })
    }

    /// The buffers under their shader names.
    pub fn named(&self) -> [(BufferName, vk::Buffer); 3] {
        [(LAYER_BUFFERS[0], self.heads.raw), (LAYER_BUFFERS[1], self.nodes.raw), (LAYER_BUFFERS[2], self.counts.raw)]
    }

    /// Pixels of the image the lists are for (a head each).
    pub fn pixels(&self) -> u64 {
        self.heads.size / 4
    }

    /// Nodes in the pool.
    pub fn capacity(&self) -> u64 {
        self.nodes.size / self.node_bytes
    }

    /// The counters as the slot's last frame left them: nodes asked for, pixels that merged,
    /// triangles listed for a work group each and for the tiles.
    pub fn counts(&self) -> [u32; 4] {
        bytemuck::pod_read_unaligned(&self.counts.mapped()[..16])
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.heads.destroy(ctx);
        self.nodes.destroy(ctx);
        self.counts.destroy(ctx);
    }
}

impl ml_vk::Release for LayerBuffers {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
