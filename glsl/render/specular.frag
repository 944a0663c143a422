#version 450 core
// The next ray of each eye path at a mirror or glass hit. Glass chooses
// reflection with probability F (exact Fresnel) and refraction otherwise, so the
// throughput needs no weight (F / F = (1 - F) / (1 - F) = 1): one path per
// pixel whose expectation equals the split tree (ARCHITECTURE.md). On a
// triangle with vertex normals the direction is taken about the shading
// normal (common/specular.glsl); the geometric normal still moves the origin.
#include "common/scene.glsl"
#include "common/random.glsl"
#include "common/specular.glsl"

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
    vec4 hn = texelFetch(u_hit_normal, px, 0);
    vec3 n = hn.xyz;
    bool entering = dot(n, d) < 0.0;
    vec3 nf = entering ? n : -n;
    vec3 throughput = ht.rgb;
    float ior = 0.0;
    float u = 0.0;
    if (kind == MAT_MIRROR) {
        throughput *= material_texel(mat, 1).rgb;
    } else {
        ior = material_texel(mat, 0).y;
        uint rng = rng_init(u_seed, uvec2(px), 0x20000000u | uint(u_depth));
        u = rng_next(rng);
    }
    int prim = int(hn.w);
    vec3 next;
    if (has_shading_normal(prim)) {
        // Vertex normals: the direction about the shading normal, falling
        // back to the geometric one where it would leave on the wrong side.
        vec3 ms = shading_normal(prim, hp.xyz, n) * (entering ? 1.0 : -1.0);
        bool used;
        next = specular_shaded(d, nf, ms, ior, entering, u, used);
    } else {
        next = specular_about(d, nf, ior, entering, u);
    }
    next = normalize(next);
    o_ray_origin = vec4(offset_origin(hp.xyz, nf, next), 1.0);
    o_ray_direction = vec4(next, 0.0);
    o_ray_throughput = vec4(throughput, 0.0);
}
