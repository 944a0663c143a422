//! Measurements of the pipeline, above `render` and `photon`: the stress
//! suite, and the library halves of `photonmap bench build`, `bench mask`
//! and `bench meshes` (their commands, and every other benchmark, live in
//! src/cli/bench/). Nothing below this module uses it.

pub mod build;
pub mod copy;
pub mod mask;
pub mod ray_rates;
pub mod regions;
pub mod stress;
pub mod throughput;
