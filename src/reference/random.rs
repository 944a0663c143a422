//! The PCG hash of glsl/common/random.glsl, bit for bit.

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
