//! The scene as the GPU-driven passes draw it (technique visibility; docs/DESIGN.md#gpu-culling):
//! the meshlet geometry, uploaded once per scene and owned by the scene's GPU resources
//! (SceneGpu), which every meshlet pass borrows — the visibility technique's culling and
//! rasters, the compute shadow raster of the point lights and the sun; per frame slot, the culling's buffers (counters with
//! the indirect dispatches and draws, the visible-instance list, the draw slots, the
//! compacted indices and triangle ids, a read-back of the counters); and, shared by the
//! slots, each meshlet instance's visibility at the end of the last frame (frames run in
//! submission order, so the next frame reads what the last one wrote). The culling, raster
//! and lighting passes share it and bind its buffers by the names the shaders give them.
//!
//! The compacted buffers hold every triangle of the scene once: a meshlet instance is drawn
//! at most once a frame (early or late), so that is their worst case — culling off.

use crate::descriptors::Resource;
use crate::frame_resources::FrameResources;
use crate::frame_resources::FRAMES_IN_FLIGHT;
use gpu_allocator::MemoryLocation;
use ml_cpu::gpu_types::{CullCounters, LargeTriangle, INSTANCE_DOUBLE_SIDED, INSTANCE_MASKED};
use ml_cpu::meshlets::SceneMeshlets;
use ml_vk::{vk, Buffer, Context, VkError};
use std::cell::RefCell;
use std::rc::Rc;

/// The culling's buffers of one frame slot.
pub struct CullFrame {
    /// CullCounters: counts, the indirect dispatches and the two phases' draws.
    pub counters: Buffer,
    /// The counters, copied after the late phase for the CPU.
    pub readback: Buffer,
    pub visible_instances: Buffer,
    /// The meshlets to draw (uvec4 each): early from 0, late from `capacity` on.
    pub draw_slots: Buffer,
    /// 3 indices per kept triangle, early then late (the raster's index buffer).
    pub indices: Buffer,
    /// A visibility id per kept triangle: early from 0, late from `triangles` on.
    pub triangle_ids: Buffer,
    /// The compute raster's large triangles, clipped, and the bins they are listed by.
    pub large_triangles: Buffer,
    pub large_bins: Buffer,
}

/// Specialization constant of the compute rasters (raster_surface.glsl SURFACE_TESTS): 1 where
/// the scene has masked or double-sided objects (`MeshletGeometry::surface_tests`).
pub const SPEC_SURFACE_TESTS: u32 = 18;

/// The scene's meshlets on the GPU, uploaded once per scene (SceneGpu owns it): what every
/// meshlet pass reads, through a `MeshletGeometryView`.
pub struct MeshletGeometry {
    pub vertices: Buffer,
    pub meshlet_vertices: Buffer,
    pub meshlet_triangles: Buffer,
    pub meshlets: Buffer,
    pub instances: Buffer,
    pub meshlet_instances: Buffer,
    /// Meshlet instances: every meshlet of every object.
    pub meshlet_instance_count: u32,
    pub instance_count: u32,
    /// Triangles of every object together.
    pub triangles: u64,
    /// Whether some object is masked or double-sided (the rasters then test surfaces).
    pub surface_tests: bool,
}

/// The buffers and counts of the scene's `MeshletGeometry`, for the passes that read it: it
/// owns nothing, and outlives no pass (the scene's GPU resources are released after them).
#[derive(Clone, Copy, Debug)]
pub struct MeshletGeometryView {
    vertices: vk::Buffer,
    meshlet_vertices: vk::Buffer,
    meshlet_triangles: vk::Buffer,
    meshlets: vk::Buffer,
    instances: vk::Buffer,
    meshlet_instances: vk::Buffer,
    pub meshlet_instance_count: u32,
    pub instance_count: u32,
    pub triangles: u64,
    pub surface_tests: bool,
}

impl MeshletGeometryView {
    /// The buffer a meshlet shader calls `name`, if it is one of these.
    pub fn buffer(&self, name: &str) -> Option<Resource> {
        let buffer = match name {
            "VertexBuffer" => self.vertices,
            "MeshletVertexBuffer" => self.meshlet_vertices,
            "MeshletTriangleBuffer" => self.meshlet_triangles,
            "MeshletBuffer" => self.meshlets,
            "InstanceBuffer" => self.instances,
            "MeshletInstanceBuffer" => self.meshlet_instances,
            _ => return None,
        };
        Some(Resource::Buffer(buffer))
    }
}

impl MeshletGeometry {
    /// `scene`'s meshlets, built and uploaded, each instance naming its object's texture set
    /// (`texture_sets`, per object: the visibility lighting binds it).
    pub fn build(ctx: &Context, scene: &ml_cpu::scene::Scene, texture_sets: &[u32]) -> Result<MeshletGeometry, VkError> {
        let mut geometry = SceneMeshlets::build(scene).map_err(|e| VkError::Limit(e.to_string()))?;
        for (instance, &set) in geometry.instances.iter_mut().zip(texture_sets) {
            instance.surface[1] = set;
        }
        MeshletGeometry::upload(ctx, &geometry)
    }

    /// Upload `g`; every buffer is bound whole as a storage buffer, so one larger than the
    /// device binds is an error, never a shortened scene.
    pub fn upload(ctx: &Context, g: &SceneMeshlets) -> Result<MeshletGeometry, VkError> {
        let geometry = MeshletGeometry {
            vertices: Buffer::null(),
            meshlet_vertices: Buffer::null(),
            meshlet_triangles: Buffer::null(),
            meshlets: Buffer::null(),
            instances: Buffer::null(),
            meshlet_instances: Buffer::null(),
            meshlet_instance_count: g.meshlet_instances.len() as u32,
            instance_count: g.instances.len() as u32,
            triangles: g.triangles,
            surface_tests: g.instances.iter().any(|i| i.meshlets[3] & (INSTANCE_DOUBLE_SIDED | INSTANCE_MASKED) != 0),
        };
        ml_vk::build(ctx, geometry, |s| {
            let upload = |name: &str, data: &[u8]| storage_buffer_with(ctx, name, data);
            s.vertices = upload("vertices", bytemuck::cast_slice(&g.vertices))?;
            s.meshlet_vertices = upload("meshlet vertices", bytemuck::cast_slice(&g.meshlet_vertices))?;
            s.meshlet_triangles = upload("meshlet triangles", bytemuck::cast_slice(&g.meshlet_triangles))?;
            s.meshlets = upload("meshlets", bytemuck::cast_slice(&g.meshlets))?;
            s.instances = upload("instances", bytemuck::cast_slice(&g.instances))?;
            s.meshlet_instances = upload("meshlet instances", bytemuck::cast_slice(&g.meshlet_instances))?;
            Ok(())
        })
    }

    /// What the passes read of it.
    pub fn view(&self) -> MeshletGeometryView {
        MeshletGeometryView {
            vertices: self.vertices.raw,
            meshlet_vertices: self.meshlet_vertices.raw,
            meshlet_triangles: self.meshlet_triangles.raw,
            meshlets: self.meshlets.raw,
            instances: self.instances.raw,
            meshlet_instances: self.meshlet_instances.raw,
            meshlet_instance_count: self.meshlet_instance_count,
            instance_count: self.instance_count,
            triangles: self.triangles,
            surface_tests: self.surface_tests,
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.vertices,
            &mut self.meshlet_vertices,
            &mut self.meshlet_triangles,
            &mut self.meshlets,
            &mut self.instances,
            &mut self.meshlet_instances,
        ] {
            b.destroy(ctx);
        }
    }
}

impl ml_vk::Release for MeshletGeometry {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// `bytes` if the device binds that many as one storage buffer, else the error that says so.
pub fn storage_bytes(ctx: &Context, name: &str, bytes: u64) -> Result<u64, VkError> {
    let max = ctx.info.limits.max_storage_buffer_range as u64;
    if bytes > max {
        return Err(VkError::Limit(format!(
            "the scene's {name} take {} MiB, more than the {} MiB '{}' binds as one storage buffer",
            bytes >> 20,
            max >> 20,
            ctx.info.name
        )));
    }
    Ok(bytes)
}

/// A device-local storage buffer holding `data` (`name` is the scene's, for the error), no
/// larger than the device binds as one storage buffer.
pub fn storage_buffer_with(ctx: &Context, name: &str, data: &[u8]) -> Result<Buffer, VkError> {
    storage_bytes(ctx, name, data.len() as u64)?;
    Buffer::device_local_with(ctx, name, data, vk::BufferUsageFlags::STORAGE_BUFFER)
}

pub struct MeshletScene {
    /// The scene's meshlets (SceneGpu's).
    pub geometry: MeshletGeometryView,
    /// Per meshlet instance: 1 where it was visible at the end of the last frame.
    pub visibility: Buffer,
    pub frames: Vec<CullFrame>,
    /// Draws one phase may write: every meshlet instance (each is drawn at most once a frame).
    pub capacity: u32,
}

/// Shared by the passes of one technique; destroyed by whichever is destroyed first.
pub type SharedMeshletScene = Rc<RefCell<MeshletScene>>;

impl MeshletScene {
    /// The scene's meshlets `geometry` with per-frame culling buffers; `bin_list`: large
    /// triangles, and bins, the compute raster's lists hold per phase (0 where it has none).
    pub fn new(ctx: &Context, geometry: MeshletGeometryView, bin_list: u32) -> Result<SharedMeshletScene, VkError> {
        let s = MeshletScene { geometry, visibility: Buffer::null(), frames: Vec::new(), capacity: geometry.meshlet_instance_count.max(1) };
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
        let bin_bytes = checked("large-triangle bins", bin_list.max(1) as u64 * 8)?;
        let large_bytes = checked("large triangles", bin_list.max(1) as u64 * std::mem::size_of::<LargeTriangle>() as u64)?;
        for _ in 0..FRAMES_IN_FLIGHT {
            let counter_bytes = std::mem::size_of::<CullCounters>() as u64;
            let mut f = CullFrame {
                counters: Buffer::null(),
                readback: Buffer::null(),
                visible_instances: Buffer::null(),
                draw_slots: Buffer::null(),
                indices: Buffer::null(),
                triangle_ids: Buffer::null(),
                large_triangles: Buffer::null(),
                large_bins: Buffer::null(),
            };
            let made = (|| {
                f.counters = Buffer::new(
                    ctx,
                    "cull counters",
                    counter_bytes,
                    storage | U::INDIRECT_BUFFER | U::TRANSFER_DST | U::TRANSFER_SRC,
                    MemoryLocation::GpuOnly,
                )?;
                f.readback = Buffer::new(ctx, "cull counters read-back", counter_bytes, U::TRANSFER_DST, MemoryLocation::GpuToCpu)?;
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
                f.large_bins = Buffer::new(ctx, "large-triangle bins", bin_bytes, storage, MemoryLocation::GpuOnly)?;
                f.large_triangles = Buffer::new(ctx, "large triangles", large_bytes, storage, MemoryLocation::GpuOnly)?;
                Ok(())
            })();
            if let Err(e) = made {
                f.destroy(ctx);
                return Err(e);
            }
            self.frames.push(f);
        }
        Ok(())
    }

    /// The buffer a culling, raster or lighting shader calls `name`, of `frame`'s slot: the
    /// scene's own, else the frame's (its uniforms, targets and scene buffers).
    pub fn buffer(&self, frame: &FrameResources, name: &str) -> Option<Resource> {
        let f = &self.frames[frame.slot];
        if let Some(found) = self.geometry.buffer(name) {
            return Some(found);
        }
        let buffer = match name {
            "MeshletVisibilityBuffer" => &self.visibility,
            "VisibleInstanceBuffer" => &f.visible_instances,
            "CullCounterBuffer" => &f.counters,
            "DrawSlotBuffer" => &f.draw_slots,
            "CompactedIndexBuffer" => &f.indices,
            "TriangleIdBuffer" => &f.triangle_ids,
            "LargeBinBuffer" => &f.large_bins,
            "LargeTriangleBuffer" => &f.large_triangles,
            _ => return frame.buffer(name),
        };
        Some(Resource::Buffer(buffer.raw))
    }

    /// Slot `slot`'s counters as its last finished frame left them.
    pub fn counters(&self, slot: usize) -> CullCounters {
        bytemuck::pod_read_unaligned(&self.frames[slot].readback.mapped()[..std::mem::size_of::<CullCounters>()])
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.visibility.destroy(ctx);
        for f in &mut self.frames {
            f.destroy(ctx);
        }
        self.frames.clear();
    }
}

impl CullFrame {
    fn destroy(&mut self, ctx: &Context) {
        for b in [
            &mut self.counters,
            &mut self.readback,
            &mut self.visible_instances,
            &mut self.draw_slots,
            &mut self.indices,
            &mut self.triangle_ids,
            &mut self.large_bins,
            &mut self.large_triangles,
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
