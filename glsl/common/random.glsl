// Per-pixel random numbers from a hash (PCG, Jarzynski & Olano 2020), so every
// sample is reproducible from (seed, pixel, stream) with no state between passes.
// src/reference/random.rs is the same code in Rust.
uint pcg_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// A generator state for one pixel and one use of it (eye ray, bounce, light sample).
uint rng_init(uint seed, uvec2 pixel, uint stream) {
    return pcg_hash(seed ^ pcg_hash(pixel.x ^ pcg_hash(pixel.y ^ pcg_hash(stream))));
}

// Uniform in [0, 1): the top 24 bits, so 1.0 is never returned.
float rng_next(inout uint state) {
    state = pcg_hash(state);
    return float(state >> 8u) * (1.0 / 16777216.0);
}
