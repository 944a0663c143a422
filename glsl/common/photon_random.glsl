// Random numbers for photon tracing: the per-photon hash by default, or (with
// RANDOM_TEXTURE, the paper's way, `--faithful`) a texture of random numbers,
// RANDOM_PER_PHOTON_FRAME (8) per photon per frame in two RGBA texels side by side. The texture is filled
// on the CPU with this very hash's values (src/photon/trace.rs), so both
// sources give the same photons.
#include "common/random.glsl"

#ifdef RANDOM_TEXTURE
uniform sampler2D u_random_numbers;
struct PhotonRandom { ivec2 texel; int next; };
PhotonRandom photon_random_init(uint seed, ivec2 global_texel, uvec2 local, uint stream) {
    return PhotonRandom(global_texel, 0);
}
float photon_random_next(inout PhotonRandom r) {
    vec4 v = texelFetch(u_random_numbers, ivec2(r.texel.x * 2 + r.next / 4, r.texel.y), 0);
    float x = v[r.next % 4];
    r.next += 1;
    return x;
}
#else
struct PhotonRandom { uint state; };
PhotonRandom photon_random_init(uint seed, ivec2 global_texel, uvec2 local, uint stream) {
    return PhotonRandom(rng_init(seed, local, stream));
}
float photon_random_next(inout PhotonRandom r) {
    return rng_next(r.state);
}
#endif
