//! The scene as the GPU-driven passes draw it (technique visibility; docs/DESIGN.md#gpu-culling):
//! the scene's meshlet geometry (scene::meshlets, borrowed) and, per frame slot, the culling's buffers (counters with
//! the indirect dispatches and draws, the visible-instance list, the draw slots, the
//! compacted indices and triangle ids) and a read-back of the counters; and, shared by the
//! slots, each meshlet instance's visibility at the end of the last frame (frames run in
//! submission order, so the next frame reads what the last one wrote). The culling, raster
//! and lighting passes share it and bind its buffers by the names the shaders give them.
//!
//! The compacted buffers hold every triangle of the scene once: a meshlet instance is drawn
//! at most once a frame (early or late), so that is their worst case — culling off. The
//! compute raster's large-triangle lists have no such bound (a near view of foliage lists
//! hundreds of thousands): a slot's lists grow when its last frame asked for more.

use crate::descriptors::Resource;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use crate::read_back::ReadBack;
use crate::scene::meshlets::{storage_bytes, MeshletGeometryView};
use crate::sync::{BufferName, MESHLET_VISIBILITY};
pub use crate::sync::{CULL_COUNTERS, LAYER_CANDIDATES};
use gpu_allocator::MemoryLocation;
use ml_cpu::gpu_types::{CullCounters, LargeTriangle};
use ml_vk::{vk, Buffer, Context, VkError};
use std::cell::RefCell;
use std::rc::Rc;

/// The culling's per-slot buffers, by their shader blocks' names: every pass that touches one
/// declares it (`Pass::uses`), and the barriers between those passes are derived (`sync`);
/// so is the meshlet visibility the slots share (`sync::MESHLET_VISIBILITY`).
pub const VISIBLE_INSTANCES: BufferName = BufferName("VisibleInstanceBuffer");
pub const DRAW_SLOTS: BufferName = BufferName("DrawSlotBuffer");
pub const COMPACTED_INDICES: BufferName = BufferName("CompactedIndexBuffer");
pub const TRIANGLE_IDS: BufferName = BufferName("TriangleIdBuffer");
pub const LARGE_BINS: BufferName = BufferName("LargeBinBuffer");
pub const LARGE_TRIANGLES: BufferName = BufferName("LargeTriangleBuffer");

/// Bytes of a layer candidate (layer_candidates.glsl: a uvec4).
const CANDIDATE_BYTES: u64 = 16;

/// The culling's buffers of one frame slot.
pub struct CullFrame {
    /// CullCounters: counts, the indirect dispatches and the two phases' draws.
    pub counters: Buffer,
    pub visible_instances: Buffer,
    /// The meshlets to draw (uvec4 each): early from 0, late from `capacity` on.
    pub draw_slots: Buffer,
    /// 3 indices per kept triangle, early then late (the raster's index buffer).
    pub indices: Buffer,
    /// A visibility id per kept triangle: early from 0, late from `triangles` on.
    pub triangle_ids: Buffer,
    /// The compute raster's large triangles, clipped, and the bins they are listed by:
    /// `large_capacity` of each (0: no lists, the large triangles go to the hardware).
    pub large_triangles: Buffer,
    pub large_bins: Buffer,
    pub large_capacity: u32,
    /// The compute raster's candidates for the transparent layers (cores of transparent
    /// objects: layer_candidates.glsl), `candidate_capacity` of them (1 where it lists none).
    pub layer_candidates: Buffer,
    pub candidate_capacity: u32,
}

pub struct MeshletScene {
    /// The scene's meshlets (SceneGpu's).
    pub geometry: MeshletGeometryView,
    /// Per meshlet instance: 1 where it was visible at the end of the last frame.
    pub visibility: Buffer,
    pub frames: Vec<CullFrame>,
    /// The counters, copied at the end of each frame for the CPU (the late culling's
    /// `host_reads`).
    pub readback: ReadBack,
    /// Draws one phase may write: every meshlet instance (each is drawn at most once a frame).
    pub capacity: u32,
    /// Whether the large-triangle lists grow (`grow_large_lists`), and the size the longest
    /// a finished frame asked for gave them: every slot's grow to it (auto exposure draws a
    /// frame again in the other slot).
    lists_grow: bool,
    grown: u32,
    /// The candidates' list's size, grown like the large-triangle lists (0: none listed).
    candidates_grown: u32,
}

/// Shared by the passes of one technique; destroyed by whichever is destroyed first.
pub type SharedMeshletScene = Rc<RefCell<MeshletScene>>;

impl MeshletScene {
    /// The scene's meshlets `geometry` with per-frame culling buffers; `bin_list`: large
    /// triangles, and bins, the compute raster's lists hold per phase at first (0 where it
    /// has none), and whether they grow; `candidates`: the layer candidates its list holds at
    /// first (0 where the raster lists none; it grows).
    pub fn new(
        ctx: &Context,
        geometry: MeshletGeometryView,
        (bin_list, lists_grow, candidates): (u32, bool, u32),
    ) -> Result<SharedMeshletScene, VkError> {
        let s = MeshletScene {
            lists_grow,
            grown: 0,
            candidates_grown: candidates,
            geometry,
            visibility: Buffer::null(),
            frames: Vec::new(),
            readback: ReadBack::new("cull counters read-back"),
            capacity: geometry.meshlet_instance_count.max(1),
        };
        let made = ml_vk::build(ctx, s, |s| s.create(ctx, bin_list))?;
        Ok(Rc::new(RefCell::new(made)))
    }

    fn create(&mut self, ctx: &Context, bin_list: u32) -> Result<(), VkError> {
        use vk::BufferUsageFlags as U;
        let storage = U::STORAGE_BUFFER;
        let checked = |name: &str, bytes: u64| storage_bytes(ctx, name, bytes);
        // Nothing was visible before the first frame: its early phase draws nothing.
        let bits = checked("meshlet visibility", self.capacity as u64 * 4)?;
        self.visibility = Buffer::device_local_with(ctx, "meshlet visibility", &vec![0u8; bits as usize], storage)?;
        let slot_bytes = checked("draw slots", 2 * self.capacity as u64 * 16)?;
        let triangles = self.geometry.triangles.max(1);
        let index_bytes = checked("compacted indices", 3 * triangles * 4)?;
        let id_bytes = checked("triangle ids", 2 * triangles * 4)?;
        for _ in 0..FRAMES_IN_FLIGHT {
            let counter_bytes = std::mem::size_of::<CullCounters>() as u64;
            let mut f = CullFrame {
                counters: Buffer::null(),
                visible_instances: Buffer::null(),
                draw_slots: Buffer::null(),
                indices: Buffer::null(),
                triangle_ids: Buffer::null(),
                large_triangles: Buffer::null(),
                large_bins: Buffer::null(),
                large_capacity: bin_list,
                layer_candidates: Buffer::null(),
                candidate_capacity: self.candidates_grown.max(1),
            };
            let made = (|| {
                f.counters = Buffer::new(
                    ctx,
                    "cull counters",
                    counter_bytes,
                    storage | U::INDIRECT_BUFFER | U::TRANSFER_DST | U::TRANSFER_SRC,
                    MemoryLocation::GpuOnly,
                )?;
                f.visible_instances = Buffer::new(
                    ctx,
                    "visible instances",
                    self.geometry.instance_count.max(1) as u64 * 4,
                    storage,
                    MemoryLocation::GpuOnly,
                )?;
                f.draw_slots = Buffer::new(ctx, "draw slots", slot_bytes, storage, MemoryLocation::GpuOnly)?;
                f.indices = Buffer::new(ctx, "compacted indices", index_bytes, storage | U::INDEX_BUFFER, MemoryLocation::GpuOnly)?;
                f.triangle_ids = Buffer::new(ctx, "triangle ids", id_bytes, storage, MemoryLocation::GpuOnly)?;
                (f.large_triangles, f.large_bins) = large_lists(ctx, bin_list)?;
                f.layer_candidates = candidate_list(ctx, f.candidate_capacity)?;
                Ok(())
            })();
            if let Err(e) = made {
                f.destroy(ctx);
                return Err(e);
            }
            self.frames.push(f);
        }
        self.readback.make_all(ctx, size_of::<CullCounters>() as u64)
    }

    /// The buffer a culling, raster or lighting shader calls `name`, of `frame`'s slot: the
    /// scene's own, else the frame's (its uniforms, targets and scene buffers).
    pub fn buffer(&self, frame: &FrameResources, name: &str) -> Option<Resource> {
        self.slot_buffer(frame.slot, name).or_else(|| frame.resource(name))
    }

    /// The scene's own buffer called `name`, of slot `slot` where it has one per slot.
    pub fn slot_buffer(&self, slot: usize, name: &str) -> Option<Resource> {
        let f = &self.frames[slot];
        if let Some(found) = self.geometry.buffer(name) {
            return Some(found);
        }
        let own = [
            (MESHLET_VISIBILITY, &self.visibility),
            (VISIBLE_INSTANCES, &f.visible_instances),
            (CULL_COUNTERS, &f.counters),
            (DRAW_SLOTS, &f.draw_slots),
            (COMPACTED_INDICES, &f.indices),
            (TRIANGLE_IDS, &f.triangle_ids),
            (LARGE_BINS, &f.large_bins),
            (LARGE_TRIANGLES, &f.large_triangles),
            (LAYER_CANDIDATES, &f.layer_candidates),
        ];
        own.iter().find(|(n, _)| n.0 == name).map(|(_, buffer)| Resource::Buffer(buffer.raw))
    }

    /// Grow slot `slot`'s large-triangle lists where its last finished frame asked for more
    /// than they hold — the triangles past them were drawn in place, each by one thread
    /// (right, but a near view of foliage took 100 ms a frame so) — to 1.5× what it asked,
    /// at most what the device binds as one storage buffer (past that, in place it stays),
    /// or where another slot's have grown longer. Returns whether they grew (the passes must
    /// then be bound to them again). Call only after the slot's fence has signalled.
    pub fn grow_large_lists(&mut self, ctx: &Context, slot: usize) -> Result<bool, VkError> {
        let Some(capacity) = self.grown_capacity(ctx, slot) else {
            return Ok(false);
        };
        self.grown = capacity;
        let (triangles, bins) = large_lists(ctx, capacity)?;
        let f = &mut self.frames[slot];
        std::mem::replace(&mut f.large_triangles, triangles).destroy(ctx);
        std::mem::replace(&mut f.large_bins, bins).destroy(ctx);
        f.large_capacity = capacity;
        Ok(true)
    }

    /// Grow slot `slot`'s layer candidates' list where its last finished frame listed more
    /// than it holds (that frame's cores were built by the per-triangle build instead: the
    /// same image, slower), to 1.5× what it listed, at most what the device binds as one
    /// storage buffer, or where another slot's has grown longer. Returns whether it grew (the
    /// passes must then be bound to it again). Call only after the slot's fence has signalled.
    pub fn grow_candidates(&mut self, ctx: &Context, slot: usize) -> Result<bool, VkError> {
        let held = self.frames[slot].candidate_capacity;
        if self.candidates_grown == 0 {
            return Ok(false);
        }
        let asked = self.counters(slot).candidates[0];
        let limit = ctx.info.limits.max_storage_buffer_range as u64 / CANDIDATE_BYTES;
        let Some(capacity) = grown_size(held, asked, limit, self.candidates_grown) else {
            return Ok(false);
        };
        self.candidates_grown = capacity;
        let list = candidate_list(ctx, capacity)?;
        let f = &mut self.frames[slot];
        std::mem::replace(&mut f.layer_candidates, list).destroy(ctx);
        f.candidate_capacity = capacity;
        Ok(true)
    }

    /// The size `grow_large_lists` would give slot `slot`'s lists; None where they stay.
    pub fn grown_capacity(&self, ctx: &Context, slot: usize) -> Option<u32> {
        let held = self.frames[slot].large_capacity;
        if !self.lists_grow || held == 0 {
            return None;
        }
        // Bins and large triangles asked for, per phase: the shader counts past the lists.
        let asked = self.counters(slot).binned.into_iter().max().unwrap_or(0);
        let limit = ctx.info.limits.max_storage_buffer_range as u64 / size_of::<LargeTriangle>() as u64;
        grown_size(held, asked, limit, self.grown)
    }

    /// Whether slot `slot`'s finished frame drew large triangles in place, which its lists,
    /// grown, would have held.
    pub fn drew_in_place_for_want_of_room(&self, ctx: &Context, slot: usize) -> bool {
        self.counters(slot).rasterized[3] > 0 && self.grown_capacity(ctx, slot).is_some()
    }

    /// Slot `slot`'s counters as its last finished frame left them.
    pub fn counters(&self, slot: usize) -> CullCounters {
        self.readback.read(slot)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.visibility.destroy(ctx);
        for f in &mut self.frames {
            f.destroy(ctx);
        }
        self.frames.clear();
        self.readback.destroy(ctx);
    }
}

/// The size a list holding `held` entries grows to after a frame that asked for `asked`: 1.5×
/// that, at most `limit`, or what another slot's list grew to (`grown`); None where it stays.
fn grown_size(held: u32, asked: u32, limit: u64, grown: u32) -> Option<u32> {
    let wanted = if asked > held { (u64::from(asked) * 3 / 2).min(limit) as u32 } else { 0 };
    let capacity = wanted.max(grown);
    (capacity > held).then_some(capacity)
}

/// The compute raster's list of `capacity` layer candidates.
fn candidate_list(ctx: &Context, capacity: u32) -> Result<Buffer, VkError> {
    let bytes = storage_bytes(ctx, "layer candidates", u64::from(capacity.max(1)) * CANDIDATE_BYTES)?;
    Buffer::new(ctx, "layer candidates", bytes, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::GpuOnly)
}

/// The compute raster's lists for `capacity` large triangles and as many bins (1 of each where
/// there are none: a binding needs a buffer).
fn large_lists(ctx: &Context, capacity: u32) -> Result<(Buffer, Buffer), VkError> {
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let entries = u64::from(capacity.max(1));
    let triangle_bytes = storage_bytes(ctx, "large triangles", entries * size_of::<LargeTriangle>() as u64)?;
    let bin_bytes = storage_bytes(ctx, "large-triangle bins", entries * 8)?;
    let triangles = Buffer::new(ctx, "large triangles", triangle_bytes, storage, MemoryLocation::GpuOnly)?;
    match Buffer::new(ctx, "large-triangle bins", bin_bytes, storage, MemoryLocation::GpuOnly) {
        Ok(bins) => Ok((triangles, bins)),
        Err(e) => {
            let mut triangles = triangles;
            triangles.destroy(ctx);
            Err(e)
        }
    }
}

impl CullFrame {
    fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.counters,
            &mut self.visible_instances,
            &mut self.draw_slots,
            &mut self.indices,
            &mut self.triangle_ids,
            &mut self.large_bins,
            &mut self.large_triangles,
            &mut self.layer_candidates,
        ] {
            b.destroy(ctx);
        }
    }
}

impl ml_vk::Release for MeshletScene {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}
