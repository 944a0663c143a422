//! Plain-Rust twins of the GPU kernels, for tests and the paper's software column.

pub mod intersect;
pub mod knn;
pub mod photon;
pub mod random;
pub mod ray_trace;
