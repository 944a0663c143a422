// The next ray of an eye path at a hit whose BSDF has a delta lobe (mirror,
// glass, smooth metal). Glass chooses
// reflection with probability F (exact Fresnel) and refraction otherwise, so the
// Fresnel weight cancels (F / F = (1 - F) / (1 - F) = 1): one path per
// pixel whose expectation equals the split tree (ARCHITECTURE.md). Where it
// refracts, the path's throughput takes radiance's (eta_i / eta_t)^2
// (common/specular.glsl): a surface seen inside glass or water is that much
// dimmer from outside. On a
// triangle with vertex normals the direction is taken about the shading
// normal (common/specular.glsl); the geometric normal still moves the origin.
// render/specular.frag (a pass per depth) and render/eye_path.frag (fused)
// share it, with the same random stream per pixel and depth.
#include "common/scene.glsl"
#include "common/random.glsl"
#include "common/bsdf.glsl"

// At hit p (geometric normal n, primitive prim) of a ray along d, where the
// surface's BSDF b has a delta lobe: the next ray's origin and direction,
// and the throughput times the lobe's factor for radiance (a mirror's
// colour, a metal's Fresnel, glass's (eta_i / eta_t)^2 where it refracts).
void specular_step(uint seed, uvec2 px, int depth, vec3 p, vec3 n, vec3 d, int prim, Bsdf b,
                   inout vec3 throughput, out vec3 origin, out vec3 next) {
    bool entering = dot(n, d) < 0.0;
    vec3 nf = entering ? n : -n;
    float u = 0.0;
    if (b.kind == MAT_GLASS) {
        uint rng = rng_init(seed, px, 0x20000000u | uint(depth));
        u = rng_next(rng);
    }
    // Vertex normals: the direction about the shading normal, falling back
    // to the geometric one where it would leave on the wrong side.
    bool shaded = has_shading_normal(prim);
    vec3 ms = nf;
    if (shaded) ms = shading_normal(prim, p, n) * (entering ? 1.0 : -1.0);
    vec3 factor;
    bool used;
    next = bsdf_delta_direction(b, d, nf, ms, shaded, entering, u, true, factor, used);
    throughput *= factor;
    next = normalize(next);
    origin = offset_origin(p, nf, next);
}
