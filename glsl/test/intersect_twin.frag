#version 450 core
// One ray per texel against primitive u_primitive: the GPU side of the
// GLSL-vs-Rust intersection twins. In mode 1 the origin is a surface point
// moved off by offset_origin first (the self-intersection test).
#include "common/scene.glsl"
uniform sampler2D u_ray_origin;    // xyz (mode 1: surface point)
uniform sampler2D u_ray_direction; // xyz unit (mode 1: w unused, normal in u_ray_normal)
uniform sampler2D u_ray_normal;
uniform int u_primitive;
uniform int u_mode;
layout(location = 0) out vec4 o_hit; // t, u, v, hit
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 o = texelFetch(u_ray_origin, px, 0).xyz;
    vec3 d = texelFetch(u_ray_direction, px, 0).xyz;
    if (u_mode == 1) o = offset_origin(o, texelFetch(u_ray_normal, px, 0).xyz, d);
    o_hit = intersect_primitive(u_primitive, o, d);
}
