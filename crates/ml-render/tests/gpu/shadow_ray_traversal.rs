//! Shadow rays' traversal on the GPU (shaders/shadows/shadow_rays.glsl) against the CPU: on the
//! shadow room and random scenes, thousands of segments between random points and the
//! scene's lights are blocked on the GPU exactly where a triangle of the scene crosses them —
//! every triangle of every object tested in world space, no hierarchy
//! (`ml_cpu::ray_bvh::WorldTriangles`) — except segments within a hair of a triangle's edge
//! or of their ends, where f32 rounding may go either way.

use ash::vk;
use glam::Vec3;
use gpu_allocator::MemoryLocation;
use ml_cpu::ray_bvh::{RayScene, WorldTriangles, RAY_STACK};
use ml_cpu::scene::Scene;
use ml_vk::{Buffer, Context, ContextDesc};
use rand::{Rng, SeedableRng};
use std::sync::atomic::Ordering;

use crate::common;

/// Per segment (start, end): whether the GPU's traversal finds it blocked.
fn gpu_blocked(ctx: &Context, rays: &RayScene, segments: &[[Vec3; 2]]) -> Vec<bool> {
    let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let upload = |name: &str, bytes: &[u8]| {
        let mut b = Buffer::new(ctx, name, bytes.len().max(4) as u64, storage, MemoryLocation::CpuToGpu).unwrap();
        b.write(0, bytes);
        b
    };
    let ends: Vec<[f32; 4]> = segments.iter().flat_map(|s| s.map(|p| p.extend(0.0).to_array())).collect();
    let mut buffers = [
        upload("top", bytemuck::cast_slice(&rays.top)),
        upload("nodes", bytemuck::cast_slice(&rays.nodes)),
        upload("triangles", bytemuck::cast_slice(&rays.triangles)),
        upload("instances", bytemuck::cast_slice(&rays.instances)),
        upload("segments", bytemuck::cast_slice(&ends)),
        Buffer::new(ctx, "blocked", (segments.len() * 4) as u64, storage, MemoryLocation::GpuToCpu).unwrap(),
    ];
    let names = ["RayTopBuffer", "RayNodeBuffer", "RayTriangleBuffer", "RayInstanceBuffer", "SegmentBuffer", "BlockedBuffer"];
    let bound: Vec<(&str, vk::Buffer)> = names.iter().zip(&buffers).map(|(n, b)| (*n, b.raw)).collect();
    common::dispatch_probe(ctx, &ml_shaders::SHADOW_RAY_PROBE_COMP, &bound, segments.len() as u32);
    let blocked: Vec<bool> = bytemuck::cast_slice::<u8, u32>(buffers[5].mapped()).iter().map(|&b| b != 0).collect();
    for b in &mut buffers {
        b.destroy(ctx);
    }
    blocked
}

/// Segments from random points in the scene's box to random lights and to other points.
fn segments(scene: &Scene, seed: u64, count: usize) -> Vec<[Vec3; 2]> {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let (lo, hi) = scene.bounds();
    let (lo, hi) = (lo - 0.2 * (hi - lo), hi + 0.2 * (hi - lo));
    let point = move |rng: &mut rand_chacha::ChaCha8Rng| {
        Vec3::new(rng.random_range(lo.x..hi.x), rng.random_range(lo.y..hi.y), rng.random_range(lo.z..hi.z))
    };
    (0..count)
        .map(|k| {
            let from = point(&mut rng);
            let to = if k % 2 == 0 && !scene.lights.is_empty() {
                Vec3::from_slice(&scene.lights[rng.random_range(0..scene.lights.len())].position_radius[..3])
            } else {
                point(&mut rng)
            };
            [from, to]
        })
        .collect()
}

#[test]
fn the_gpu_traversal_blocks_exactly_the_segments_a_triangle_crosses() {
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("Vulkan with validation");
    let counter = ctx.validation_counter();
    let scenes = [
        ("shadow room", Scene::shadow_room()),
        ("random 1", ml_cpu::random_scene::random_scene(1, 16)),
        ("random 2", ml_cpu::random_scene::random_scene(2, 16)),
    ];
    for (seed, (name, scene)) in scenes.iter().enumerate() {
        let rays = RayScene::build(scene);
        assert!(rays.stack_needed() <= RAY_STACK);
        let world = WorldTriangles::new(scene);
        let segs = segments(scene, seed as u64, 3000);
        let gpu = gpu_blocked(&ctx, &rays, &segs);
        let (mut blocked, mut checked) = (0, 0);
        for (s, g) in segs.iter().zip(&gpu) {
            let cpu = rays.occluded(s[0], s[1]);
            if !world.sure(s[0], s[1], 1e-4, 1e-4) {
                continue;
            }
            let expected = world.occluded(s[0], s[1]);
            assert_eq!(cpu, expected, "{name}: the CPU traversal, {} -> {}", s[0], s[1]);
            assert_eq!(*g, expected, "{name}: the GPU traversal, {} -> {}", s[0], s[1]);
            blocked += usize::from(expected);
            checked += 1;
        }
        assert!(checked > 2000 && blocked > checked / 20 && blocked < checked * 19 / 20, "{name}: {blocked} of {checked} blocked");
        println!("{name}: {checked} segments, {blocked} blocked, GPU = CPU = every triangle");
    }
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages");
}
