// The next ray of an eye path at a mirror or glass hit. Glass chooses
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
#include "common/specular.glsl"

// At hit p (geometric normal n, primitive prim, material mat of kind kind,
// mirror or glass) of a ray along d: the next ray's origin and direction, and
// the throughput times the mirror's colour or, where it refracts, radiance's
// scale.
void specular_step(uint seed, uvec2 px, int depth, vec3 p, vec3 n, vec3 d, int prim, int mat,
                   int kind, inout vec3 throughput, out vec3 origin, out vec3 next) {
    bool entering = dot(n, d) < 0.0;
    vec3 nf = entering ? n : -n;
    float ior = 0.0;
    float u = 0.0;
    if (kind == MAT_MIRROR) {
        throughput *= material_texel(mat, 1).rgb;
    } else {
        ior = material_texel(mat, 0).y;
        uint rng = rng_init(seed, px, 0x20000000u | uint(depth));
        u = rng_next(rng);
    }
    if (has_shading_normal(prim)) {
        // Vertex normals: the direction about the shading normal, falling
        // back to the geometric one where it would leave on the wrong side.
        vec3 ms = shading_normal(prim, p, n) * (entering ? 1.0 : -1.0);
        bool used;
        next = specular_shaded(d, nf, ms, ior, entering, u, used);
    } else {
        next = specular_about(d, nf, ior, entering, u);
    }
    throughput *= radiance_refraction_scale(next, nf, ior, entering);
    next = normalize(next);
    origin = offset_origin(p, nf, next);
}
