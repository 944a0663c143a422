#version 450 core
// Direct light at the diffuse hits of this depth by shadow rays, and emitters
// seen along the path (common/direct_light.glsl). Drawn with additive
// blending: one call per batch of shadow samples adds its share. It also records
// the first diffuse hit of each eye path, where the radiance estimate will add
// indirect light and caustics: an eye path ends at its diffuse hit, so each
// pixel's record is written once and the blend onto zero copies it. Later
// batches of a depth draw into the radiance target alone.
#include "common/direct_light.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_hit_position;
uniform sampler2D u_hit_normal;
uniform sampler2D u_hit_throughput;
uniform sampler2D u_hit_direction;
uniform uint u_seed;
uniform int u_depth;
uniform int u_shadow_rays;   // N per area light
uniform int u_strata_x;      // N = strata_x * strata_y
uniform int u_sample_begin;  // this batch: samples [begin, end)
uniform int u_sample_end;
uniform int u_light_sampling; // 0: no shadow rays (direct light comes from photons)

layout(location = 0) out vec4 o_radiance;
layout(location = 1) out vec4 o_diffuse_position;   // xyz, w = 1 where recorded
layout(location = 2) out vec4 o_diffuse_normal;     // facing the viewer, w = material + 1
layout(location = 3) out vec4 o_diffuse_throughput; // path throughput up to the hit, w = primitive

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    o_diffuse_position = vec4(0.0);
    o_diffuse_normal = vec4(0.0);
    o_diffuse_throughput = vec4(0.0);
    vec4 hp = texelFetch(u_hit_position, px, 0);
    vec4 ht = texelFetch(u_hit_throughput, px, 0);
    // Nothing to add (the blend would add zeros): discard, which skips the
    // blend's read and write of every target.
    if (hp.w < 0.0 || ht.w == 0.0) discard;
    int mat = int(hp.w);
    Bsdf b = material_bsdf(mat);
    vec3 d = texelFetch(u_hit_direction, px, 0).xyz;
    vec4 hn = texelFetch(u_hit_normal, px, 0);
    bool first_batch = u_sample_begin == 0;

    if (b.kind == MAT_EMITTER) {
        if (!first_batch) discard;
        o_radiance = vec4(ht.rgb * emitter_seen(mat, hn.xyz, d), 0.0);
        return;
    }
    if (!bsdf_is_diffuse(b)) discard;
    int prim = int(hn.w);
    vec3 nf;
    vec3 sum = direct_light(u_seed, uvec2(px), u_depth, hp.xyz, hn.xyz, d, prim, mat,
                              first_batch, u_sample_begin, u_sample_end, u_shadow_rays,
                              u_strata_x, u_light_sampling != 0, nf);
    o_radiance = vec4(ht.rgb * bsdf_lambert(b) * sum, 0.0);
    if (first_batch) {
        o_diffuse_position = vec4(hp.xyz, 1.0);
        o_diffuse_normal = vec4(nf, float(mat + 1));
        o_diffuse_throughput = vec4(ht.rgb, float(prim));
    }
}
