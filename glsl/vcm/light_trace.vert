#version 450 core
// Light tracing, VCM's technique with no camera vertex: each stored light
// vertex (one point per record) connected to the pinhole, drawn at the pixel
// it projects to with its contribution, which vcm/light_trace.frag adds
// into the light image (additive blending). A vertex that projects outside
// the image, faces away, is hidden from the camera or makes too long a path
// is dropped (off screen). Its contribution is light tracing's estimate of
// the pixel's mean radiance (SmallVCM's ConnectToCamera): the vertex's power
// x BRDF x the area pdf with which the camera would sample it, x its weight.
#include "common/camera.glsl"
#include "vcm/mis.glsl"
#include "vcm/light_vertex.glsl"

uniform int u_mode;
uniform int u_max_segments;

flat out vec3 v_contribution;

void main() {
    gl_PointSize = 1.0;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    v_contribution = vec3(0.0);
    LightVertex v;
    if (!light_vertex(texel_of_index(gl_VertexID, u_lv_width), v)) return;
    if (v.segments + 1 > u_max_segments) return;
    vec3 forward = -u_camera_backward;
    vec3 rel = v.p - u_camera_position;
    float depth = dot(rel, forward);
    if (depth <= 0.0) return;
    vec2 ndc = vec2(dot(rel, u_camera_right) / (depth * u_tan_half_fov.x),
                    dot(rel, u_camera_up) / (depth * u_tan_half_fov.y));
    if (abs(ndc.x) >= 1.0 || abs(ndc.y) >= 1.0) return;
    float dist = length(rel);
    vec3 to_camera = -rel / dist;
    // It reflects on the side its light arrived from.
    vec3 side = dot(v.n, v.incoming) < 0.0 ? v.n : -v.n;
    float cos_light = dot(side, to_camera);
    if (cos_light <= 0.0) return;
    if (occluded_toward(u_camera_position, v.p + offset_scale(v.p) * side)) return;
    float cos_camera = depth / dist;
    float image_distance = u_image_size.y / (2.0 * u_tan_half_fov.y);
    float camera_pdf_w = image_distance * image_distance / (cos_camera * cos_camera * cos_camera);
    float camera_pdf_a = camera_pdf_w * cos_light / (dist * dist);
    float w = 1.0;
    if (u_mode != VCM_MODE_LT) {
        float rev = continuation(v.albedo) * abs(dot(v.n, v.incoming)) / PI;
        w = mis_camera_connection_weight(v.partials, camera_pdf_a, rev);
    }
    v_contribution = w * v.power * (v.albedo / PI) * camera_pdf_a;
    gl_Position = vec4(ndc, 0.0, 1.0);
}
