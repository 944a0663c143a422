#version 450 core
// Light tracing, VCM's technique with no camera vertex, part one: each light
// vertex of this iteration's map (one fragment a texel of the map, the
// stored vertices compacted) connected to the pinhole. It writes the
// vertex's contribution and where it lands; vcm/light_splat.vert then draws
// one point a texel there, and the splat adds it into the light image. The
// shadow ray runs here, in a fragment pass, because a draw's vertices are
// shaded on one thread (llvmpipe) while its fragments use every core.
// A vertex that projects outside the image, faces away, is hidden from the
// camera or makes too long a path lands nowhere (w = 0). Its contribution
// is light tracing's estimate of the pixel's mean radiance (SmallVCM's
// ConnectToCamera): the vertex's power x BRDF x the area pdf with which the
// camera would sample it, x its weight.
#include "common/camera.glsl"
#include "vcm/mis.glsl"
#include "vcm/light_vertex.glsl"

uniform isampler2D u_map_pairs;   // the map's (slot, record), compacted
uniform int u_sorted_width;
uniform int u_max_segments;

layout(location = 0) out vec4 o_contribution; // rgb
layout(location = 1) out vec4 o_landing;      // ndc xy, w = 1 where it lands

void main() {
    o_contribution = vec4(0.0);
    o_landing = vec4(0.0);
    int index = index_of_texel(ivec2(gl_FragCoord.xy), u_sorted_width);
    if (index >= u_light_vertices) return;
    int record = texelFetch(u_map_pairs, ivec2(gl_FragCoord.xy), 0).y;
    LightVertex v;
    if (!light_vertex(texel_of_index(record, u_lv_width), v)) return;
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
    if (VCM_MODE != VCM_MODE_LT) {
        float rev = camera_continuation(continuation(v.albedo)) * abs(dot(v.n, v.incoming)) / PI;
        w = mis_camera_connection_weight(v.partials, camera_pdf_a, rev);
    }
    o_contribution = vec4(w * v.power * (v.albedo / PI) * camera_pdf_a, 0.0);
    o_landing = vec4(ndc, 0.0, 1.0);
}
