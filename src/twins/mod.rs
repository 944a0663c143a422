//! Plain-Rust twins of the GPU kernels, which tests compare each kernel with;
//! compiled only with the `twins` feature (the package's own tests enable it).

pub mod adaptive;
pub mod bsdf;
pub mod bvh;
pub mod differentials;
pub mod final_gather;
pub mod igi;
pub mod intersect;
pub mod knn;
pub mod light;
pub mod path_trace;
pub mod photon;
pub mod radiosity;
pub mod random;
pub mod ray_trace;
pub mod shading;
pub mod sppm;
pub mod vcm;
