#version 450 core
// Closest hit of every active ray: the hit textures that the direct-light,
// specular and (later) radiance-estimate passes read.
#include "common/scene.glsl"

uniform sampler2D u_ray_origin;
uniform sampler2D u_ray_direction;
uniform sampler2D u_ray_throughput;

layout(location = 0) out vec4 o_hit_position;   // xyz, w = material (-1: nothing)
layout(location = 1) out vec4 o_hit_normal;     // geometric normal, w = primitive
layout(location = 2) out vec4 o_hit_throughput; // rgb, w = 1 while the path lives
layout(location = 3) out vec4 o_hit_direction;  // incoming unit direction, w = t

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 origin = texelFetch(u_ray_origin, px, 0);
    vec3 d = texelFetch(u_ray_direction, px, 0).xyz;
    vec3 throughput = texelFetch(u_ray_throughput, px, 0).rgb;
    o_hit_position = vec4(0.0, 0.0, 0.0, -1.0);
    o_hit_normal = vec4(0.0, 0.0, 0.0, -1.0);
    o_hit_throughput = vec4(0.0);
    o_hit_direction = vec4(d, 0.0);
    if (origin.w == 0.0) return;
    vec4 hit;
    int prim = closest_hit(origin.xyz, d, hit);
    if (prim < 0) return; // background radiance is zero
    vec3 n;
    vec3 p = surface_point(prim, origin.xyz, d, hit, n);
    o_hit_position = vec4(p, float(primitive_material(prim)));
    o_hit_normal = vec4(n, float(prim));
    o_hit_throughput = vec4(throughput, 1.0);
    o_hit_direction = vec4(d, hit.x);
}
