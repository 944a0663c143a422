#version 450 core
// One ray per texel: the GPU side of the GLSL-vs-Rust intersection twins.
// Mode 0: against primitive u_primitive; mode 1: the same from a surface
// point moved off by offset_origin first (the self-intersection test);
// mode 2: closest_hit over the whole scene (the BVH), w = the primitive or -1;
// mode 3: occluded() up to the direction's w, as 1 or 0.
#include "common/scene.glsl"
uniform sampler2D u_ray_origin;    // xyz (mode 1: surface point)
uniform sampler2D u_ray_direction; // xyz unit (mode 3: w = t_max)
uniform sampler2D u_ray_normal;
uniform int u_primitive;
uniform int u_mode;
layout(location = 0) out vec4 o_hit; // t, u, v, hit
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 o = texelFetch(u_ray_origin, px, 0).xyz;
    vec4 d = texelFetch(u_ray_direction, px, 0);
    if (u_mode == 2) {
        vec4 best;
        int prim = closest_hit(o, d.xyz, best);
        o_hit = vec4(best.xyz, float(prim));
        return;
    }
    if (u_mode == 3) {
        o_hit = vec4(occluded(o, d.xyz, d.w) ? 1.0 : 0.0);
        return;
    }
    if (u_mode == 1) o = offset_origin(o, texelFetch(u_ray_normal, px, 0).xyz, d.xyz);
    o_hit = intersect_primitive(u_primitive, o, d.xyz);
}
