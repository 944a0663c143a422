//! The PCG hash of glsl/common/random.glsl, bit for bit: the random-number
//! texture of `--faithful`, eye-sample seeds and the twins all draw from it.

pub fn pcg_hash(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

pub fn rng_init(seed: u32, pixel: [u32; 2], stream: u32) -> u32 {
    pcg_hash(seed ^ pcg_hash(pixel[0] ^ pcg_hash(pixel[1] ^ pcg_hash(stream))))
}

pub fn rng_next(state: &mut u32) -> f32 {
    *state = pcg_hash(*state);
    (*state >> 8) as f32 * (1.0 / 16777216.0)
}

/// The seed of eye sample `sample`: the render's own for sample 0 (so one
/// sample per pixel is exactly the paper's render), a hash of it for the rest.
pub fn sample_seed(seed: u32, sample: u32) -> u32 {
    if sample == 0 {
        seed
    } else {
        pcg_hash(seed ^ pcg_hash(sample.wrapping_add(0x5bd1e995)))
    }
}

/// Shuffles `values` in place (Fisher-Yates) with the stream `state`: the
/// Halton digit permutations and IGI's VPL order draw from it.
pub fn shuffle<T>(values: &mut [T], state: &mut u32) {
    for i in (1..values.len()).rev() {
        let j = ((rng_next(state) * (i + 1) as f32) as usize).min(i);
        values.swap(i, j);
    }
}
