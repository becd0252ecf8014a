//! Static meshes in device-local memory, uploaded once through a staging buffer (seed 000).

use ml_cpu::mesh::{Mesh, MeshKind};
use ml_vk::{vk, Buffer, Context, VkError};

pub struct GpuMesh {
    pub kind: MeshKind,
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
}

impl GpuMesh {
    pub fn upload(ctx: &Context, kind: MeshKind, mesh: &Mesh) -> Result<GpuMesh, VkError> {
        let mut vertices =
            Buffer::device_local_with(ctx, "vertices", bytemuck::cast_slice(&mesh.vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?;
        match Buffer::device_local_with(ctx, "indices", bytemuck::cast_slice(&mesh.indices), vk::BufferUsageFlags::INDEX_BUFFER) {
            Ok(indices) => Ok(GpuMesh { kind, vertices, indices, index_count: mesh.indices.len() as u32 }),
            Err(e) => {
                vertices.destroy(ctx);
                Err(e)
            }
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
    }
}
