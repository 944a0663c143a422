#version 450 core
// The MIS partials of every vertex of one light path (vcm/mis.glsl), walked
// from its emission record through the frames photon tracing wrote, and
// stored beside each record (dVCM, dVC, dVM, segments from the light) for
// the camera paths, the light tracing splats and the merging to read. A
// diffuse vertex is left by a cosine-distributed direction about its
// geometric normal, continued with its largest albedo channel's probability
// (a camera path there with camera_continuation of it);
// a mirror or glass by a delta. src/twins/vcm.rs is the twin of the
// recurrences.
#include "common/scene.glsl"
#include "vcm/mis.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_position;
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform sampler2D u_outgoing;
layout(rgba32f) uniform writeonly image2D u_partials_out;
uniform int u_frame_height;
uniform int u_frames;

layout(location = 0) out vec4 o_unused;

// The light that emitted the photon whose emission record is (p, prim): the
// emitting primitive's light, or the point light at p.
int emitting_light(vec3 p, int prim) {
    if (prim >= 0) return primitive_light(prim);
    for (int l = 0; l < u_light_count; ++l)
        if (light_kind_is(light_kind(l), LIGHT_POINT) && light_texel(l, 1).xyz == p) return l;
    return -1;
}

void main() {
    ivec2 local = ivec2(gl_FragCoord.xy);
    o_unused = vec4(0.0);
    vec4 p0 = texelFetch(u_position, local, 0);
    vec4 out0 = texelFetch(u_outgoing, local, 0);
    if (texelFetch(u_incoming, local, 0).w == 0.0) return; // not emitted
    int l = emitting_light(p0.xyz, int(out0.w));
    if (l < 0) return;
    float pick = light_texel(l, 5).y;
    bool delta = light_kind_is(light_kind(l), LIGHT_POINT);
    vec3 partials;
    if (delta) {
        partials = mis_light_start(pick, pick / (4.0 * PI), 1.0, true);
    } else {
        AreaLight L = area_light(l);
        vec3 n = L.triangles ? geometric_normal(int(out0.w), p0.xyz) : L.normal;
        float cos_light = abs(dot(n, out0.xyz));
        float direct_pdf_a = pick / L.area;
        partials = mis_light_start(direct_pdf_a, direct_pdf_a * cos_light / PI, cos_light, false);
    }
    vec3 last = p0.xyz;
    vec3 d = out0.xyz;
    for (int b = 1; b < u_frames; ++b) {
        ivec2 texel = local + ivec2(0, b * u_frame_height);
        vec4 position = texelFetch(u_position, texel, 0);
        if (position.w < 0.0) return; // it left the scene or met a light
        vec4 incoming = texelFetch(u_incoming, texel, 0);
        vec4 outgoing = texelFetch(u_outgoing, texel, 0);
        int prim = int(outgoing.w);
        vec3 n = geometric_normal(prim, position.xyz);
        float cos_in = abs(dot(n, d));
        partials = mis_arrive(partials, distance(position.xyz, last), cos_in, true);
        imageStore(u_partials_out, texel, vec4(partials, float(b)));
        if (incoming.w == 0.0) return; // absorbed
        int mat = int(position.w);
        float cos_out = abs(dot(n, outgoing.xyz));
        Bsdf bsdf = material_bsdf(mat);
        if (bsdf_is_diffuse(bsdf)) {
            vec3 albedo = bsdf.color;
            float q = max(albedo.r, max(albedo.g, albedo.b));
            partials = mis_scatter(partials, cos_out, q * cos_out / PI,
                                   camera_continuation(q) * cos_in / PI);
        } else {
            partials = mis_scatter_specular(partials, cos_out);
        }
        last = position.xyz;
        d = outgoing.xyz;
    }
}
