//! The slice formula is written once in Rust (`ClusterGrid::slice`) and once in GLSL
//! (`cluster_slice` in shaders/clusters/cluster.glsl). On 10⁵ random depths the GPU's slices
//! must equal the CPU's, except for depths within 1e-4 slices of a boundary, where f32 `log`
//! may round either way — and there they may differ by one slice only (the cluster boxes
//! carry slack for exactly that).

use ash::vk;
use gpu_allocator::MemoryLocation;
use ml_cpu::camera::{Camera, View};
use ml_cpu::cluster::{ClusterDims, ClusterGrid};
use ml_cpu::gpu_types::FrameUniforms;
use ml_vk::{Buffer, Context, ContextDesc};
use rand::{Rng, SeedableRng};
use std::sync::atomic::Ordering;

use crate::common;

const COUNT: usize = 100_000;

fn gpu_slices(ctx: &Context, grid: &ClusterGrid, depths: &[f32]) -> Vec<u32> {
    let frame = FrameUniforms {
        cluster_dims: [grid.dims.x, grid.dims.y, grid.dims.z, 0],
        viewport: [grid.width, grid.height, 0, 0],
        cluster_slices: [grid.log_scale, grid.log_bias, 1.0, 0.0],
        ..Default::default()
    };
    let mut uniforms =
        Buffer::new(ctx, "uniforms", size_of::<FrameUniforms>() as u64, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::CpuToGpu)
            .unwrap();
    uniforms.write(0, &[frame]);
    let mut input =
        Buffer::new(ctx, "depths", (depths.len() * 4) as u64, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::CpuToGpu).unwrap();
    input.write(0, depths);
    let mut output =
        Buffer::new(ctx, "slices", (depths.len() * 4) as u64, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::GpuToCpu).unwrap();
    let buffers = [("FrameBlock", uniforms.raw), ("DepthBuffer", input.raw), ("SliceBuffer", output.raw)];
    common::dispatch_probe(ctx, &ml_shaders::CLUSTER_SLICE_PROBE_COMP, &buffers, depths.len() as u32);
    let slices: Vec<u32> = bytemuck::cast_slice(output.mapped()).to_vec();
    for b in [&mut uniforms, &mut input, &mut output] {
        b.destroy(ctx);
    }
    slices
}

#[test]
fn glsl_and_rust_slices_agree_on_random_depths() {
    let ctx = Context::new(&ContextDesc { validation: true, ..Default::default() }).expect("Vulkan with validation");
    let counter = ctx.validation_counter();
    let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(Camera::seed(), 1920, 1080));
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    // Uniform in log depth (like the slices), plus some out of [near, far].
    let depths: Vec<f32> = (0..COUNT).map(|_| grid.near * (grid.far / grid.near).powf(rng.random_range(-0.05..1.05))).collect();
    let gpu = gpu_slices(&ctx, &grid, &depths);
    drop(ctx);
    assert_eq!(counter.load(Ordering::SeqCst), 0, "validation messages");
    let (mut boundary, mut differ) = (0, 0);
    for (d, g) in depths.iter().zip(&gpu) {
        let cpu = grid.slice(*d);
        let s = d.ln() as f64 * grid.log_scale as f64 + grid.log_bias as f64;
        let near_boundary = (s - s.round()).abs() < 1e-4;
        boundary += near_boundary as u32;
        if cpu != *g {
            differ += 1;
            assert!(near_boundary && cpu.abs_diff(*g) == 1, "depth {d}: CPU slice {cpu}, GPU slice {g}");
        }
    }
    println!("{COUNT} depths: {differ} differ by one slice, all within 1e-4 slices of a boundary ({boundary} such depths)");
}
