//! The scene's meshlet geometry on the GPU (docs/DESIGN.md#meshlets): built and uploaded once
//! per scene and owned by the scene's GPU resources, which every meshlet pass borrows — the
//! visibility technique's culling and rasters, and the compute shadow rasters of the point
//! lights and the sun. A light-count change does not rebuild it.

use crate::descriptors::Resource;
use crate::error::RenderError;
use ml_cpu::gpu_types::{INSTANCE_DOUBLE_SIDED, INSTANCE_MASKED};
use ml_cpu::meshlets::SceneMeshlets;
use ml_vk::{vk, Buffer, Context, VkError};

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
    /// Whether some object is masked or double-sided (the rasters then test surfaces: their
    /// specialization constant `SURFACE_TESTS`, visibility/raster_surface.glsl).
    pub surface_tests: bool,
    /// Whether some object is masked (`MASK_TESTS`).
    pub mask_tests: bool,
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
    pub mask_tests: bool,
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

    /// The compute rasters' specialization constants `SURFACE_TESTS` and `MASK_TESTS`
    /// (name, value).
    pub fn surface_constants(&self) -> [(&'static str, u32); 2] {
        [("SURFACE_TESTS", u32::from(self.surface_tests)), ("MASK_TESTS", u32::from(self.mask_tests))]
    }
}

impl MeshletGeometry {
    /// `scene`'s meshlets, built and uploaded, each instance naming its object's texture set
    /// (`texture_sets`, per object: the visibility lighting binds it).
    pub fn build(ctx: &Context, scene: &ml_cpu::scene::Scene, texture_sets: &[u32]) -> Result<MeshletGeometry, RenderError> {
        let mut geometry = SceneMeshlets::build(scene).map_err(|e| RenderError::Invalid(e.to_string()))?;
        for (instance, &set) in geometry.instances.iter_mut().zip(texture_sets) {
            instance.surface[1] = set;
        }
        Ok(MeshletGeometry::upload(ctx, &geometry)?)
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
            mask_tests: g.instances.iter().any(|i| i.meshlets[3] & INSTANCE_MASKED != 0),
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
            mask_tests: self.mask_tests,
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
        return Err(VkError::DeviceLimit(format!(
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
