//! Plain-Rust twins of the GPU kernels, for tests and the paper's software column.

pub mod adaptive;
pub mod bvh;
pub mod differentials;
pub mod final_gather;
pub mod igi;
pub mod intersect;
pub mod knn;
pub mod path_trace;
pub mod photon;
pub mod radiosity;
pub mod random;
pub mod ray_trace;
pub mod shading;
pub mod sppm;
