//! The shadow rays' hierarchy on the GPU (`ml_cpu::ray_bvh`, docs/DESIGN.md#shadow-rays):
//! built on the CPU with the scene's objects (again whenever they are replaced) and uploaded
//! once; one-element stand-ins where no light casts shadow rays (every lighting pipeline
//! binds the five buffers; only SHADOW_RAYS pipelines read them).

use crate::error::RenderError;
use crate::report::FeatureStats;
use crate::sync::BufferName;
use ml_cpu::gpu_types::{RayInstance, RayNode, RayTriangle};
use ml_cpu::ray_bvh::{RayScene, RAY_STACK};
use ml_cpu::scene::Scene;
use ml_vk::{vk, Buffer, Context};

/// What the hierarchy took (the `render` table's row).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RayStats {
    pub build_ms: f64,
    pub bytes: u64,
    pub nodes: usize,
    pub triangles: usize,
    pub instances: usize,
    /// Most entries a traversal keeps on its stack (RayScene::stack_needed).
    pub depth: usize,
    /// The rays the last frame traced from its opaque surfaces, counted with `--light-stats`
    /// (which the compute lightings alone take).
    pub traced: Option<u64>,
}

impl FeatureStats for RayStats {
    fn rows(&self) -> Vec<(&'static str, String)> {
        let mib = self.bytes as f64 / (1 << 20) as f64;
        let traced = self.traced.map_or_else(String::new, |n| format!("; {n} rays traced in the last frame"));
        vec![(
            "shadow rays",
            format!(
                "hierarchy of {} triangles (each mesh once), {} nodes, {} instances, a traversal stack of {} at most: {mib:.1} MiB, built in {:.1} ms on the CPU{traced}",
                self.triangles, self.nodes, self.instances, self.depth, self.build_ms
            ),
        )]
    }
}

pub struct RayGeometry {
    top: Buffer,
    nodes: Buffer,
    triangles: Buffer,
    instances: Buffer,
    uvs: Buffer,
    /// None for the stand-ins.
    pub stats: Option<RayStats>,
}

impl RayGeometry {
    /// Nothing uploaded yet.
    pub fn null() -> RayGeometry {
        RayGeometry {
            top: Buffer::null(),
            nodes: Buffer::null(),
            triangles: Buffer::null(),
            instances: Buffer::null(),
            uvs: Buffer::null(),
            stats: None,
        }
    }

    /// `scene`'s hierarchy if `rays`, else stand-ins.
    pub fn new(ctx: &Context, scene: &Scene, rays: bool) -> Result<RayGeometry, RenderError> {
        let built = if rays { RayScene::build(scene) } else { RayScene::default() };
        if built.stack_needed() > RAY_STACK {
            return Err(RenderError::Invalid(format!(
                "the scene's shadow-ray hierarchy needs a traversal stack of {} entries, more than the {RAY_STACK} the shaders keep: use shadow cubes (--omni-shadow atlas)",
                built.stack_needed()
            )));
        }
        let mut geometry = RayGeometry::null();
        let made = geometry.upload(ctx, &built);
        if let Err(e) = made {
            geometry.destroy(ctx);
            return Err(e.into());
        }
        geometry.stats = rays.then(|| RayStats {
            build_ms: built.build_ms,
            bytes: built.bytes(),
            nodes: built.nodes.len() + built.top.len(),
            triangles: built.triangles.len(),
            instances: built.instances.len(),
            depth: built.stack_needed(),
            traced: None,
        });
        Ok(geometry)
    }

    fn upload(&mut self, ctx: &Context, built: &RayScene) -> Result<(), ml_vk::VkError> {
        // A stand-in element where a part is empty (a buffer has a size).
        fn or_one<T: bytemuck::Pod + Default>(items: &[T]) -> Vec<T> {
            if items.is_empty() {
                vec![T::default()]
            } else {
                items.to_vec()
            }
        }
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let upload = |name: &str, bytes: &[u8]| Buffer::device_local_with(ctx, name, bytes, storage);
        self.top = upload("shadow-ray top level", bytemuck::cast_slice(&or_one::<RayNode>(&built.top)))?;
        self.nodes = upload("shadow-ray nodes", bytemuck::cast_slice(&or_one::<RayNode>(&built.nodes)))?;
        self.triangles = upload("shadow-ray triangles", bytemuck::cast_slice(&or_one::<RayTriangle>(&built.triangles)))?;
        self.instances = upload("shadow-ray instances", bytemuck::cast_slice(&or_one::<RayInstance>(&built.instances)))?;
        self.uvs = upload("shadow-ray texture coordinates", bytemuck::cast_slice(&or_one::<[f32; 2]>(&built.uvs)))?;
        Ok(())
    }

    /// The buffers under the shaders' block names (common/scene_bindings.glsl).
    pub fn named_buffers(&self) -> [(BufferName, vk::Buffer); 5] {
        [
            (BufferName("RayTopBuffer"), self.top.raw),
            (BufferName("RayNodeBuffer"), self.nodes.raw),
            (BufferName("RayTriangleBuffer"), self.triangles.raw),
            (BufferName("RayInstanceBuffer"), self.instances.raw),
            (BufferName("RayUvBuffer"), self.uvs.raw),
        ]
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for b in [&mut self.top, &mut self.nodes, &mut self.triangles, &mut self.instances, &mut self.uvs] {
            b.destroy(ctx);
        }
        self.stats = None;
    }
}
