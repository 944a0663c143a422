// VCM's light vertices: the records photon tracing writes (photon/trace.frag
// names their channels; every diffuse hit is stored), with the MIS partials
// vcm/light_partials.frag adds beside them (dVCM, dVC, dVM, path length in
// segments from the light). A vertex's throughput is the photon's power
// times the light paths traced (N): the power is already per light path.
// vcm/camera_path.frag and vcm/light_connect.frag read them.
#include "common/scene.glsl"
#include "common/addressing.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_lv_position;  // xyz, w = material (-1: on the light)
uniform sampler2D u_lv_power;     // rgb arriving, w = 1 stored (a diffuse hit)
uniform sampler2D u_lv_incoming;  // direction of arrival
uniform sampler2D u_lv_outgoing;  // w = primitive hit
uniform sampler2D u_lv_partials;  // dVCM, dVC, dVM, segments from the light
uniform int u_lv_width;           // frame width
uniform int u_lv_frame_height;
uniform int u_lv_frames;          // frames holding a live photon
uniform float u_lv_power_scale;
uniform int u_light_vertices;     // stored this iteration: the map's count (0: none)

struct LightVertex {
    vec3 p;
    vec3 n;        // geometric normal
    vec3 incoming; // direction of travel into the vertex
    vec3 power;    // per light path (throughput / N)
    vec3 partials;
    vec3 albedo;
    int segments;
};

// The stored vertex at `texel` of the records, or false where that record
// is no stored diffuse vertex of this iteration.
bool light_vertex(ivec2 texel, out LightVertex v) {
    vec4 power = texelFetch(u_lv_power, texel, 0);
    if (power.w == 0.0) return false;
    vec4 position = texelFetch(u_lv_position, texel, 0);
    int prim = int(texelFetch(u_lv_outgoing, texel, 0).w);
    vec4 partials = texelFetch(u_lv_partials, texel, 0);
    v.p = position.xyz;
    v.n = geometric_normal(prim, v.p);
    v.incoming = texelFetch(u_lv_incoming, texel, 0).xyz;
    v.power = power.rgb * u_lv_power_scale;
    v.partials = partials.xyz;
    v.albedo = material_bsdf(int(position.w)).color; // a diffuse lobe's albedo
    v.segments = int(partials.w);
    return true;
}

// Russian roulette's continuation probability at a diffuse vertex: its
// largest albedo channel (photon/bounce.glsl, and the camera paths alike).
float continuation(vec3 albedo) {
    return max(albedo.r, max(albedo.g, albedo.b));
}
