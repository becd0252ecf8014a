//! Static meshes in device-local memory, uploaded once through a staging buffer (docs/DESIGN.md#conventions).

use ml_cpu::mesh::{Mesh, MeshKind, Vertex};
use ml_cpu::scene::Object;
use ml_vk::{vk, Buffer, Context, VkError};

pub struct GpuMesh {
    pub kind: MeshKind,
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
}

impl GpuMesh {
    pub fn upload(ctx: &Context, kind: MeshKind, mesh: &Mesh) -> Result<GpuMesh, VkError> {
        // The transparent layers' compute build copies the small meshes into buffers of its own.
        let copied = vk::BufferUsageFlags::TRANSFER_SRC;
        let mut vertices =
            Buffer::device_local_with(ctx, "vertices", bytemuck::cast_slice(&mesh.vertices), vk::BufferUsageFlags::VERTEX_BUFFER | copied)?;
        match Buffer::device_local_with(ctx, "indices", bytemuck::cast_slice(&mesh.indices), vk::BufferUsageFlags::INDEX_BUFFER | copied) {
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

/// Transparent objects of at most this many triangles have their layers built over tiles
/// (transparent_build_compute.glsl), the others a thread per triangle
/// (transparent_build_triangles.glsl), unless the settings say otherwise
/// (`TransparencySettings::tiled_up_to`).
pub const COMPUTE_LAYER_TRIANGLES: u32 = 64;

/// Where `o` is a transparent object, the index of its mesh among `meshes`.
pub fn layer_mesh(o: &Object, meshes: &[GpuMesh]) -> Option<usize> {
    if o.extras.alpha_mode != ml_cpu::scene::AlphaMode::Blend {
        return None;
    }
    meshes.iter().position(|m| m.kind == o.mesh)
}

/// The vertex buffer's binding (one, per vertex) as pipelines read it.
pub fn vertex_binding() -> vk::VertexInputBindingDescription {
    vk::VertexInputBindingDescription::default()
        .binding(0)
        .stride(std::mem::size_of::<Vertex>() as u32)
        .input_rate(vk::VertexInputRate::VERTEX)
}

/// Every `Vertex` field as a vertex attribute, location = field order (forward.vert): position,
/// normal, uv, tangent. A pipeline that needs only the first few takes a prefix.
pub fn vertex_attributes() -> [vk::VertexInputAttributeDescription; 4] {
    use std::mem::offset_of;
    [
        (vk::Format::R32G32B32_SFLOAT, offset_of!(Vertex, position)),
        (vk::Format::R32G32B32_SFLOAT, offset_of!(Vertex, normal)),
        (vk::Format::R32G32_SFLOAT, offset_of!(Vertex, uv)),
        (vk::Format::R32G32B32A32_SFLOAT, offset_of!(Vertex, tangent)),
    ]
    .into_iter()
    .enumerate()
    .map(|(location, (format, offset))| {
        vk::VertexInputAttributeDescription::default().location(location as u32).binding(0).format(format).offset(offset as u32)
    })
    .collect::<Vec<_>>()
    .try_into()
    .expect("four attributes")
}

/// Record the indexed draws of `objects` whose instance mask (`instances(index in the scene)`:
/// bit i asks for instance i; 0 skips the object) is not empty: per mesh, its buffers bound, then its
/// objects in scene order, each after `push(index in the scene, object)` (which records the
/// draw's push constants), one draw per run of consecutive instances.
pub fn record_draws(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    (meshes, objects): (&[GpuMesh], &[Object]),
    instances: impl Fn(u32) -> u32,
    mut push: impl FnMut(u32, &Object),
) {
    let d = &ctx.device;
    for mesh in meshes {
        let mut bound = false;
        for (index, object) in objects.iter().enumerate().filter(|(_, o)| o.mesh == mesh.kind) {
            let mut mask = instances(index as u32);
            if mask == 0 {
                continue;
            }
            // SAFETY: recording state inside a render pass with a pipeline bound; the
            // buffers are alive while the command buffer is.
            unsafe {
                if !bound {
                    d.cmd_bind_vertex_buffers(cmd, 0, &[mesh.vertices.raw], &[0]);
                    d.cmd_bind_index_buffer(cmd, mesh.indices.raw, 0, vk::IndexType::UINT32);
                    bound = true;
                }
                push(index as u32, object);
                while mask != 0 {
                    let first = mask.trailing_zeros();
                    let count = (mask >> first).trailing_ones();
                    d.cmd_draw_indexed(cmd, mesh.index_count, count, 0, 0, first);
                    mask &= !((((1u64 << count) - 1) as u32) << first);
                }
            }
        }
    }
}
