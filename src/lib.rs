//! photonmap-gl: Purcell et al., "Photon Mapping on Programmable Graphics
//! Hardware" (Graphics Hardware 2003), as OpenGL fragment passes, headless.
//! ARCHITECTURE.md maps each box of the paper's Figure 1 to a module here.
//!
//! Dependencies run one way: render -> photon -> scene -> gpu, and every one
//! of them may use the leaf modules (error, layout, random, sampling, timing,
//! image). `bench` (the benchmarks and the stress suite) sits above render.
//! `twins` holds the plain-Rust twins of the kernels, built only for tests
//! (the `twins` feature).
#![deny(unsafe_code)]

pub mod bench;
pub mod error;
pub mod gpu;
pub mod image;
pub mod interrupt;
pub mod layout;
pub mod metrics;
pub mod photon;
pub mod provenance;
pub mod random;
pub mod regress;
pub mod render;
pub mod sampling;
pub mod scene;
pub mod timing;
/// Plain-Rust twins of the GPU kernels, compiled only with the `twins`
/// feature, which the package's own tests enable (a dev-dependency on itself),
/// so production code cannot name them.
#[cfg(feature = "twins")]
pub mod twins;

pub use error::{Error, Result};

// The fuzz harness (tests/fuzz/harness.rs), shared with the cargo-fuzz crate,
// names this library `photonmap`; the loader's unit tests include it.
#[cfg(test)]
extern crate self as photonmap;
