#version 450 core
// Eye rays through the pixel centres of a pinhole camera (the paper's one ray per
// pixel), starting each eye path with throughput 1.
uniform vec3 u_camera_position;
uniform vec3 u_camera_right;    // u
uniform vec3 u_camera_up;       // v
uniform vec3 u_camera_backward; // w: the camera looks down -w
uniform vec2 u_tan_half_fov;    // (horizontal, vertical)
uniform vec2 u_image_size;
uniform vec2 u_subpixel;        // (0.5, 0.5) = the pixel centre

layout(location = 0) out vec4 o_ray_origin;     // xyz, w = active
layout(location = 1) out vec4 o_ray_direction;  // xyz unit
layout(location = 2) out vec4 o_ray_throughput; // rgb

void main() {
    vec2 ndc = (floor(gl_FragCoord.xy) + u_subpixel) / u_image_size * 2.0 - 1.0;
    vec3 d = -u_camera_backward + ndc.x * u_tan_half_fov.x * u_camera_right
             + ndc.y * u_tan_half_fov.y * u_camera_up;
    o_ray_origin = vec4(u_camera_position, 1.0);
    o_ray_direction = vec4(normalize(d), 0.0);
    o_ray_throughput = vec4(1.0);
}
