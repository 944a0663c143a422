//! Where photon tracing takes its random numbers: a PCG hash in the shader,
//! or (IGI's VPLs, Keller's quasi-random walk) the scrambled Halton sequence
//! computed here, a dimension per random number of each frame.

/// Where photon tracing takes its random numbers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum RandomSource {
    /// A PCG hash of (seed, photon, bounce) in the shader.
    Hash,
    /// The paper's way: a texture of random numbers, 8 per photon per frame,
    /// filled on the CPU from the seed (with the hash's own sequence, so both
    /// sources trace the same photons).
    Texture,
    /// Quasi-random numbers through the same texture (instant radiosity's
    /// light paths, as Keller and Marques and Santos draw them): photon i's
    /// numbers are the scrambled Halton sequence's point i (`ScrambledHalton`,
    /// digits permuted by the seed) in the first `HALTON_DIMENSIONS`
    /// dimensions (the emission and the first bounces); later ones take the
    /// hash's numbers.
    Halton,
}

/// Dimensions drawn from the Halton sequence (the first 54 primes): the
/// emission's numbers and those of the first 16 bounces.
pub const HALTON_DIMENSIONS: usize = 54;

/// The prime bases of the Halton dimensions.
const PRIMES: [u32; HALTON_DIMENSIONS] = [
    2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97,
    101, 103, 107, 109, 113, 127, 131, 137, 139, 149, 151, 157, 163, 167, 173, 179, 181, 191, 193,
    197, 199, 211, 223, 227, 229, 233, 239, 241, 251,
];

/// Random numbers a photon draws at emission (light, two for the point, two
/// for the direction; projection maps draw one more, which is never a Halton
/// one) and at each bounce (glsl/photon/emit.frag, bounce.glsl).
const EMISSION_NUMBERS: usize = 5;
const BOUNCE_NUMBERS: usize = 3;

/// The Halton dimension of number `k` of frame `frame`, if it has one: the
/// numbers actually drawn take consecutive dimensions, so the first bounces
/// get the small bases, whose points are evenly spread even for few paths.
pub(super) fn halton_dimension(frame: usize, k: usize) -> Option<usize> {
    let dim = match frame {
        0 => (k < EMISSION_NUMBERS).then_some(k)?,
        f => (k < BOUNCE_NUMBERS).then_some(EMISSION_NUMBERS + BOUNCE_NUMBERS * (f - 1) + k)?,
    };
    (dim < HALTON_DIMENSIONS).then_some(dim)
}

/// The scrambled Halton sequence of one seed: a random permutation of the
/// digits of each dimension's base (random-digit scrambling, as pbrt-v4's
/// Halton sampler does), applied to every digit down to below f32 precision.
/// Unscrambled, the large bases give the first points i / b in every
/// dimension, nearly on a line; scrambled, each dimension's points stay
/// stratified and the dimensions are decorrelated.
pub struct ScrambledHalton {
    permutations: Vec<Vec<u32>>,
}

impl ScrambledHalton {
    pub fn new(seed: u32) -> Self {
        let permutations = PRIMES
            .iter()
            .enumerate()
            .map(|(dim, &base)| {
                let mut state = crate::random::rng_init(seed, [dim as u32, 0], 0x7000_0000);
                let mut p: Vec<u32> = (0..base).collect();
                crate::random::shuffle(&mut p, &mut state);
                p
            })
            .collect();
        Self { permutations }
    }

    /// Point `index`'s number in dimension `dim` (< HALTON_DIMENSIONS), in [0, 1).
    pub fn number(&self, dim: usize, mut index: u64) -> f32 {
        let base = PRIMES[dim] as u64;
        let perm = &self.permutations[dim];
        let inv = 1.0 / base as f64;
        let (mut factor, mut v) = (inv, 0.0f64);
        while factor > 1e-9 {
            v += perm[(index % base) as usize] as f64 * factor;
            index /= base;
            factor *= inv;
        }
        // Rounding to f32 may reach 1.0; the shaders expect [0, 1).
        (v as f32).min(1.0 - f32::EPSILON / 2.0)
    }
}
