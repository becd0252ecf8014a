//! Clustered light assignment (`clustered-cpu`, docs/DESIGN.md#clustered-light-assignment):
//! the view frustum split into X×Y screen tiles and Z exponential depth slices; for every
//! cluster, the lights whose sphere can reach a point inside it.

mod assign;
mod grid;

pub use assign::{count_entries, ClusterAssigner, ClusterLists, ClusterStats, ListsTooLong};
pub use grid::{Aabb, ClusterDims, ClusterGrid};

#[cfg(test)]
mod tests;
