#version 450 core
// The next ray of each eye path at a mirror or glass hit. Glass chooses
// reflection with probability F (exact Fresnel) and refraction otherwise, so the
// throughput needs no weight (F / F = (1 - F) / (1 - F) = 1): one path per
// pixel whose expectation equals the split tree (ARCHITECTURE.md).
#include "common/scene.glsl"
#include "common/random.glsl"
#include "common/fresnel.glsl"

uniform sampler2D u_hit_position;
uniform sampler2D u_hit_normal;
uniform sampler2D u_hit_throughput;
uniform sampler2D u_hit_direction;
uniform uint u_seed;
uniform int u_depth;

layout(location = 0) out vec4 o_ray_origin;
layout(location = 1) out vec4 o_ray_direction;
layout(location = 2) out vec4 o_ray_throughput;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_ray_origin = vec4(0.0);
    o_ray_direction = vec4(0.0);
    o_ray_throughput = vec4(0.0);
    vec4 hp = texelFetch(u_hit_position, px, 0);
    vec4 ht = texelFetch(u_hit_throughput, px, 0);
    if (hp.w < 0.0 || ht.w == 0.0) return;
    int mat = int(hp.w);
    int kind = material_kind(mat);
    if (kind != MAT_MIRROR && kind != MAT_GLASS) return;
    vec3 d = texelFetch(u_hit_direction, px, 0).xyz;
    vec3 n = texelFetch(u_hit_normal, px, 0).xyz;
    bool entering = dot(n, d) < 0.0;
    vec3 nf = entering ? n : -n;
    float cos_i = -dot(d, nf);
    vec3 throughput = ht.rgb;
    vec3 next;
    if (kind == MAT_MIRROR) {
        next = reflect(d, nf);
        throughput *= material_texel(mat, 1).rgb;
    } else {
        float ior = material_texel(mat, 0).y;
        float eta = entering ? 1.0 / ior : ior;
        float cos_t;
        float f = fresnel_dielectric(cos_i, eta, cos_t);
        uint rng = rng_init(u_seed, uvec2(px), 0x20000000u | uint(u_depth));
        if (rng_next(rng) < f) {
            next = reflect(d, nf);
        } else {
            next = eta * d + (eta * cos_i - cos_t) * nf;
        }
    }
    next = normalize(next);
    o_ray_origin = vec4(offset_origin(hp.xyz, nf, next), 1.0);
    o_ray_direction = vec4(next, 0.0);
    o_ray_throughput = vec4(throughput, 0.0);
}
