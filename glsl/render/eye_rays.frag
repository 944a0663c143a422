#version 450 core
// Eye rays of a pinhole camera, starting each eye path with throughput 1:
// through the pixel centres (the paper's one ray per pixel), or with several
// samples per pixel through a jittered point of this sample's stratum.
#include "common/random.glsl"
uniform vec3 u_camera_position;
uniform vec3 u_camera_right;    // u
uniform vec3 u_camera_up;       // v
uniform vec3 u_camera_backward; // w: the camera looks down -w
uniform vec2 u_tan_half_fov;    // (horizontal, vertical)
uniform vec2 u_image_size;
uniform int u_jitter;           // 0: pixel centre
uniform int u_sample;           // stratum index
uniform ivec2 u_strata;         // strata per pixel (x, y)
uniform uint u_seed;

layout(location = 0) out vec4 o_ray_origin;     // xyz, w = active
layout(location = 1) out vec4 o_ray_direction;  // xyz unit
layout(location = 2) out vec4 o_ray_throughput; // rgb

void main() {
    vec2 sub = vec2(0.5);
    if (u_jitter != 0) {
        uint rng = rng_init(u_seed, uvec2(gl_FragCoord.xy), 0x30000000u | uint(u_sample));
        vec2 stratum = vec2(u_sample % u_strata.x, u_sample / u_strata.x);
        sub = (stratum + vec2(rng_next(rng), rng_next(rng))) / vec2(u_strata);
    }
    vec2 ndc = (floor(gl_FragCoord.xy) + sub) / u_image_size * 2.0 - 1.0;
    vec3 d = -u_camera_backward + ndc.x * u_tan_half_fov.x * u_camera_right
             + ndc.y * u_tan_half_fov.y * u_camera_up;
    o_ray_origin = vec4(u_camera_position, 1.0);
    o_ray_direction = vec4(normalize(d), 0.0);
    o_ray_throughput = vec4(1.0);
}
