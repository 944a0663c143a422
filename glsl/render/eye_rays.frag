#version 450 core
// Eye rays of a pinhole camera (common/camera.glsl), starting each eye path
// with throughput 1.
#include "common/camera.glsl"
uniform uint u_seed;

layout(location = 0) out vec4 o_ray_origin;     // xyz, w = active
layout(location = 1) out vec4 o_ray_direction;  // xyz unit
layout(location = 2) out vec4 o_ray_throughput; // rgb

void main() {
    o_ray_origin = vec4(u_camera_position, 1.0);
    o_ray_direction = vec4(eye_ray_direction(uvec2(gl_FragCoord.xy), u_seed), 0.0);
    o_ray_throughput = vec4(1.0);
}
