//! Light assignment to the cluster grid: on the CPU each frame (clustered-cpu,
//! deferred-clustered) or built on the GPU (clustered-gpu, deferred-compute, visibility)
//! (docs/DESIGN.md#clustered-light-assignment).

pub mod cluster_assign_cpu;
pub mod cluster_build;
