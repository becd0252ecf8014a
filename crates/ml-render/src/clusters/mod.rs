//! Light assignment to the cluster grid on the CPU each frame (clustered-cpu,
//! deferred-clustered; docs/DESIGN.md#clustered-light-assignment). The GPU techniques use
//! the light grid (`crate::light_grid`).

pub mod cluster_assign_cpu;
