#version 450 core
// The next ray of each eye path at a hit of this depth whose BSDF has a
// delta lobe (mirror, glass, smooth metal)
// (common/specular_step.glsl).
#include "common/specular_step.glsl"

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
    Bsdf b = material_bsdf(int(hp.w));
    if (!bsdf_is_delta(b)) return;
    vec3 d = texelFetch(u_hit_direction, px, 0).xyz;
    vec4 hn = texelFetch(u_hit_normal, px, 0);
    vec3 throughput = ht.rgb;
    vec3 origin, next;
    specular_step(u_seed, uvec2(px), u_depth, hp.xyz, hn.xyz, d, int(hn.w), b, throughput,
                  origin, next);
    o_ray_origin = vec4(origin, 1.0);
    o_ray_direction = vec4(next, 0.0);
    o_ray_throughput = vec4(throughput, 0.0);
}
