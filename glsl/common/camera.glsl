// A pinhole camera's eye ray through pixel `px`: through its centre (the
// paper's one ray per pixel), or with several samples per pixel through a
// jittered point of this sample's stratum. render/eye_rays.frag and the fused
// render/eye_path.frag share it.
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

// The unit direction of the eye ray (it starts at u_camera_position).
vec3 eye_ray_direction(uvec2 px, uint seed) {
    vec2 sub = vec2(0.5);
    if (u_jitter != 0) {
        uint rng = rng_init(seed, px, 0x30000000u | uint(u_sample));
        vec2 stratum = vec2(u_sample % u_strata.x, u_sample / u_strata.x);
        sub = (stratum + vec2(rng_next(rng), rng_next(rng))) / vec2(u_strata);
    }
    vec2 ndc = (vec2(px) + sub) / u_image_size * 2.0 - 1.0;
    vec3 d = -u_camera_backward + ndc.x * u_tan_half_fov.x * u_camera_right
             + ndc.y * u_tan_half_fov.y * u_camera_up;
    return normalize(d);
}
