//! CPU light assignment alone: 16×9×24 grid, 1920×1080, the seed camera, random lights of
//! radius 1–3 in the benchmark box (x,z ∈ [−20, 20], y ∈ [−2, 12]).
//! Run: `cargo bench -p ml-cpu --features criterion --bench cluster_assign`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use ml_cpu::camera::{Camera, View};
use ml_cpu::cluster::{ClusterAssigner, ClusterDims, ClusterGrid, ClusterLists};
use ml_cpu::lights::{LightLayout, LightParams, RadiusRange};

fn assign(c: &mut Criterion) {
    let grid = ClusterGrid::new(ClusterDims::DEFAULT, &View::new(Camera::seed(), 1920, 1080));
    let mut group = c.benchmark_group("cluster_assign_16x9x24_1080p");
    for count in [1_000u32, 10_000, 100_000] {
        let lights =
            LightParams { count, layout: LightLayout::Random, seed: 1, radius: RadiusRange { min: 1.0, max: 3.0 } }.build().unwrap();
        let mut assigner = ClusterAssigner::new();
        let mut lists = ClusterLists::default();
        group.bench_with_input(BenchmarkId::from_parameter(count), &lights, |b, lights| {
            b.iter(|| assigner.assign(&grid, lights, &mut lists, usize::MAX).expect("no limit"));
        });
        let s = lists.stats();
        println!("{count} lights: lights/cluster mean {:.2} max {}, index list {}", s.mean_lights, s.max_lights, s.index_len);
    }
    group.finish();
}

criterion_group!(benches, assign);
criterion_main!(benches);
