//! The twins draw the same random numbers as the kernels through the
//! library's own PCG hash (`crate::random`), which the random-number texture
//! test checks bit for bit against glsl/common/random.glsl.

pub use crate::random::{pcg_hash, rng_init, rng_next};
