//! The GPU test suite, one binary: a module per kernel or stage, each on the
//! real GL pipeline (llvmpipe in CI) and against its plain-Rust twin where it
//! has one. `cargo test --release --test gpu` runs it all; a module alone is
//! `cargo test --release --test gpu sppm::`.

#[path = "../common/mod.rs"]
mod common;

mod adaptive;
mod bias_compensation;
mod bit_identical;
mod bsdf;
mod bvh;
mod caustic_footprints;
mod differentials;
mod final_gather;
mod fused_eye_path;
mod gpu_substrate;
mod hash_grid;
mod igi;
mod import;
mod intersections;
mod obj_scenes;
mod photon_build;
mod photon_trace;
mod platforms;
mod radiance_estimate;
mod radiosity;
mod radiosity_caustics;
mod radiosity_gather;
mod ray_tracer;
mod reference_images;
mod sppm;
mod stress;
mod truth;
mod vcm;
