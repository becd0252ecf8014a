//! Static meshes in device-local memory, uploaded once through a staging buffer (docs/DESIGN.md#conventions).

use ml_cpu::mesh::{Mesh, MeshKind, Vertex};
use ml_cpu::scene::{Object, Scene};
use ml_vk::{vk, Buffer, Context, VkError};
use std::collections::HashMap;

/// One mesh of the scene: its ranges of the scene's vertex and index buffers (its indices
/// count from its first vertex).
pub struct GpuMesh {
    pub first_vertex: u32,
    pub vertex_count: u32,
    pub first_index: u32,
    pub index_count: u32,
}

/// Every mesh of a scene in one vertex buffer and one index buffer, found by kind. (A pair of
/// buffers per mesh made a valid file of 100,000 one-quad meshes spend minutes allocating
/// them, each allocation searching the allocator's free list.)
pub struct SceneMeshes {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub meshes: Vec<GpuMesh>,
    by_kind: HashMap<MeshKind, usize>,
}

impl SceneMeshes {
    pub fn empty() -> SceneMeshes {
        SceneMeshes { vertices: Buffer::null(), indices: Buffer::null(), meshes: Vec::new(), by_kind: HashMap::new() }
    }

    /// The meshes `scene`'s objects draw, uploaded.
    pub fn upload(ctx: &Context, scene: &Scene) -> Result<SceneMeshes, VkError> {
        let (mut vertices, mut indices): (Vec<Vertex>, Vec<u32>) = (Vec::new(), Vec::new());
        let mut made = SceneMeshes::empty();
        for kind in scene.mesh_kinds() {
            let mesh: Mesh = scene.mesh(kind).ok_or_else(|| VkError::Interface(format!("the scene has no mesh {kind:?}")))?;
            let (first_vertex, first_index) = (vertices.len(), indices.len());
            // A draw's vertex offset is signed.
            if first_vertex + mesh.vertices.len() > i32::MAX as usize || first_index + mesh.indices.len() > u32::MAX as usize {
                return Err(VkError::DeviceLimit(format!(
                    "the scene's meshes hold more than {} vertices or {} indices",
                    i32::MAX,
                    u32::MAX
                )));
            }
            vertices.extend_from_slice(&mesh.vertices);
            indices.extend_from_slice(&mesh.indices);
            made.by_kind.insert(kind, made.meshes.len());
            made.meshes.push(GpuMesh {
                first_vertex: first_vertex as u32,
                vertex_count: mesh.vertices.len() as u32,
                first_index: first_index as u32,
                index_count: mesh.indices.len() as u32,
            });
        }
        // The transparent layers' compute build copies the small meshes into buffers of its own.
        let copied = vk::BufferUsageFlags::TRANSFER_SRC;
        ml_vk::build(ctx, made, |made| {
            made.vertices =
                Buffer::device_local_with(ctx, "vertices", bytemuck::cast_slice(&vertices), vk::BufferUsageFlags::VERTEX_BUFFER | copied)?;
            made.indices =
                Buffer::device_local_with(ctx, "indices", bytemuck::cast_slice(&indices), vk::BufferUsageFlags::INDEX_BUFFER | copied)?;
            Ok(())
        })
    }

    /// Where the mesh `kind` is among `meshes`.
    pub fn index_of(&self, kind: MeshKind) -> Option<usize> {
        self.by_kind.get(&kind).copied()
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
        self.meshes.clear();
        self.by_kind.clear();
    }
}

impl ml_vk::Release for SceneMeshes {
    fn release(&mut self, ctx: &Context) {
        self.destroy(ctx);
    }
}

/// Transparent objects of at most this many triangles have their layers built over tiles
/// (transparent_build_compute.glsl), the others a thread per triangle
/// (transparent_build_triangles.glsl), unless the settings say otherwise
/// (`TransparencySettings::tiled_up_to`).
pub const COMPUTE_LAYER_TRIANGLES: u32 = 64;

/// Where `o` is a transparent object, the index of its mesh among `meshes`.
pub fn layer_mesh(o: &Object, meshes: &SceneMeshes) -> Option<usize> {
    if !o.extras.transparent() {
        return None;
    }
    meshes.index_of(o.mesh)
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
    (meshes, objects): (&SceneMeshes, &[Object]),
    instances: impl Fn(u32) -> u32,
    mut push: impl FnMut(u32, &Object),
) {
    let d = &ctx.device;
    // The objects by mesh, each mesh's in scene order (a sort, not a pass over the objects
    // per mesh: a scene may hold as many meshes as objects).
    let mut order: Vec<(usize, u32)> =
        objects.iter().enumerate().filter_map(|(index, o)| Some((meshes.index_of(o.mesh)?, index as u32))).collect();
    order.sort_unstable();
    let mut bound = false;
    for (m, index) in order {
        let mut mask = instances(index);
        if mask == 0 {
            continue;
        }
        let mesh = &meshes.meshes[m];
        // SAFETY: recording state inside a render pass with a pipeline bound; the buffers are
        // alive while the command buffer is.
        unsafe {
            if !bound {
                d.cmd_bind_vertex_buffers(cmd, 0, &[meshes.vertices.raw], &[0]);
                d.cmd_bind_index_buffer(cmd, meshes.indices.raw, 0, vk::IndexType::UINT32);
                bound = true;
            }
            push(index, &objects[index as usize]);
            while mask != 0 {
                let first = mask.trailing_zeros();
                let count = (mask >> first).trailing_ones();
                d.cmd_draw_indexed(cmd, mesh.index_count, count, mesh.first_index, mesh.first_vertex as i32, first);
                mask &= !((((1u64 << count) - 1) as u32) << first);
            }
        }
    }
}
