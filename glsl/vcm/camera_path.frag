#version 450 core
// One pixel's camera path of vertex connection and merging, whole, in one
// pass: from a jittered eye ray through mirrors and glass (as eye paths go,
// common/specular_step.glsl) and on past diffuse vertices by cosine
// sampling and Russian roulette. At each diffuse vertex it takes
// - next-event estimation: one point on one light, picked by power;
// - connections to light vertices drawn from all of this iteration's (the
//   light vertex cache: the map's compacted vertices, vcm/light_vertex.glsl);
// - merging with the light vertices of this iteration's map within the
//   radius (the map's photons are the light vertices);
// and where it meets a light, the light's radiance. Each is weighted by the
// balance heuristic over every technique that could make its path
// (vcm/mis.glsl). Light tracing, the one technique with no camera vertex,
// is vcm/light_connect.frag's. VCM_MODE chooses the techniques: one of
// VCM_MODE_* (src/render/vcm/options.rs names them), compiled in, so that
// the techniques a mode leaves out cost nothing (llvmpipe would run their
// branches under an empty lane mask).
#include "common/camera.glsl"
#include "common/direct_light.glsl"
#include "common/specular_step.glsl"
#include "common/sampling.glsl"
#include "common/photon_map.glsl"
#include "vcm/mis.glsl"
#include "vcm/light_vertex.glsl"

uniform uint u_seed;
uniform int u_max_segments;       // longest path, in segments
uniform float u_radius2;          // merging radius squared
uniform isampler2D u_map_pairs;   // sorted (key, record): a map photon's record
uniform sampler2D u_map_incoming;
uniform int u_merge;              // 1: merging runs
uniform int u_connections;        // light vertices a camera vertex connects to

layout(location = 0) out vec4 o_radiance;
// What each technique carried (their sum is o_radiance): lights hit,
// next-event estimation, connections to light vertices, merging.
layout(location = 1) out vec4 o_emission;
layout(location = 2) out vec4 o_light_sample;
layout(location = 3) out vec4 o_connection;
layout(location = 4) out vec4 o_merging;

bool connections() { return VCM_MODE == VCM_MODE_VCM || VCM_MODE == VCM_MODE_BPT; }

// One light picked by power, and a point on it: the radiance it sends
// toward x, the direction and distance to it, the pdfs (pick x solid angle
// at x, pick x emission) and the cosine at the light; false when it sends
// nothing toward x (its back, or x on it).
bool sample_light(inout uint rng, vec3 x, out vec3 radiance, out vec3 wi, out float dist,
                  out float direct_pdf_w, out float emission_pdf_w, out float cos_light,
                  out bool delta) {
    float pick = rng_next(rng);
    int l = 0;
    while (l < u_light_count - 1 && pick >= light_texel(l, 5).x) ++l;
    float p = light_texel(l, 5).y;
    float u1 = rng_next(rng), u2 = rng_next(rng);
    radiance = light_texel(l, 4).rgb;
    delta = light_kind_is(light_kind(l), LIGHT_POINT);
    vec3 q, normal;
    float area = 1.0;
    if (delta) {
        q = light_texel(l, 1).xyz;
    } else {
        AreaLight L = area_light(l);
        q = area_light_point(l, L, u1, u2, normal);
        area = L.area;
    }
    vec3 to = q - x;
    dist = length(to);
    if (!(dist > 0.0)) return false;
    wi = to / dist;
    if (delta) {
        cos_light = 1.0;
        direct_pdf_w = p * dist * dist;
        emission_pdf_w = p / (4.0 * PI);
        return true;
    }
    cos_light = -dot(normal, wi);
    if (cos_light <= 0.0) return false;
    direct_pdf_w = p / area * dist * dist / cos_light;
    emission_pdf_w = p / area * cos_light / PI;
    return true;
}

// Merging at camera vertex x (normal nf facing where the path came from,
// albedo a, continuation q of camera paths and q_light of light paths,
// arriving cosine cos_in, `segments` from the camera): the sum over this
// iteration's light vertices within the radius of weight x BRDF x power,
// over pi r^2.
vec3 merge(vec3 x, vec3 nf, vec3 a, float q, float q_light, float cos_in, vec3 camera,
           int segments) {
    float r = sqrt(u_radius2);
    vec3 cell_size = (u_grid_max - u_grid_min) / vec3(u_grid_resolution);
    ivec3 lo = clamp(ivec3(floor((x - r - u_grid_min) / cell_size)), ivec3(0), u_grid_resolution - 1);
    ivec3 hi = clamp(ivec3(floor((x + r - u_grid_min) / cell_size)), ivec3(0), u_grid_resolution - 1);
    vec3 sum = vec3(0.0);
    float camera_rev_pdf_w = q_light * cos_in / PI;
    for (int cz = lo.z; cz <= hi.z; ++cz)
        for (int cy = lo.y; cy <= hi.y; ++cy)
            for (int cx = lo.x; cx <= hi.x; ++cx) {
                int cell = cx + u_grid_resolution.x * (cy + u_grid_resolution.y * cz);
                int base;
                int count = cell_photon_count(cell, base);
                if (count == 0) continue;
                // No division a photon (photon_texel_next; see sppm_gather.glsl).
                ivec2 origin = photon_block_origin(base);
                ivec2 t = photon_texel(base, 0);
                for (int i = 0; i < count; ++i, t = photon_texel_next(t, origin)) {
                    vec3 photon = texelFetch(u_map_position, t, 0).xyz;
                    vec3 offset = photon - x;
                    if (dot(offset, offset) >= u_radius2) continue;
                    if (!photon_in_cell(photon, cell)) continue;
                    vec3 incoming = texelFetch(u_map_incoming, t, 0).xyz;
                    float cos_light = -dot(incoming, nf);
                    if (cos_light <= 0.0) continue; // it arrives on the other side
                    int record = texelFetch(u_map_pairs, t, 0).y;
                    vec4 partials = texelFetch(u_lv_partials, texel_of_index(record, u_lv_width), 0);
                    if (int(partials.w) + segments > u_max_segments) continue;
                    float w = VCM_MODE == VCM_MODE_PPM ? 1.0
                            : mis_merge_weight(camera, partials.xyz, q * cos_light / PI, camera_rev_pdf_w);
                    sum += w * texelFetch(u_map_power, t, 0).rgb;
                }
            }
    return sum * (a / PI) / (PI * u_radius2);
}

// Connections from camera vertex x to u_connections light vertices drawn
// uniformly from all `count` of this iteration (Davidovic et al. 2014's light
// vertex cache). Scaled by count / (N u_connections), the sum is in
// expectation the connections to every vertex of one light path, so each
// path length is connected as often as that and the MIS weights stand.
vec3 connect(inout uint rng, int count, vec3 x, vec3 nf, vec3 a, float q, float q_light,
             float cos_in, vec3 camera, int segments) {
    vec3 sum = vec3(0.0);
    vec3 origin = x + offset_scale(x) * nf;
    for (int c = 0; c < u_connections; ++c) {
        int index = min(int(rng_next(rng) * float(count)), count - 1);
        int record = texelFetch(u_map_pairs, texel_of_index(index, u_sorted_width), 0).y;
        LightVertex v;
        if (!light_vertex(texel_of_index(record, u_lv_width), v)) continue;
        if (v.segments + segments + 1 > u_max_segments) continue;
        vec3 to = v.p - x;
        float d2 = dot(to, to);
        float dist = sqrt(d2);
        vec3 dir = to / dist;
        float cos_camera = dot(nf, dir);
        // The light vertex reflects on the side its light arrived from.
        vec3 light_side = dot(v.n, v.incoming) < 0.0 ? v.n : -v.n;
        float cos_light = -dot(light_side, dir);
        if (cos_camera <= 0.0 || cos_light <= 0.0) continue;
        if (occluded_toward(origin, v.p + offset_scale(v.p) * light_side)) continue;
        float q_vertex = continuation(v.albedo);
        float light_cos_in = abs(dot(v.n, v.incoming));
        float w = mis_vertex_connection_weight(camera, v.partials,
            q * cos_camera / PI * cos_light / d2, q_light * cos_in / PI,
            q_vertex * cos_light / PI * cos_camera / d2,
            camera_continuation(q_vertex) * light_cos_in / PI);
        sum += w * (v.albedo / PI) * v.power * (cos_camera * cos_light / d2);
    }
    // v.power is per light path (throughput / N): x N, then x count / (N n).
    return sum * (float(count) / float(u_connections)) * (a / PI);
}

void main() {
    uvec2 px = uvec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    vec3 o = u_camera_position;
    vec3 d = eye_ray_direction(px, u_seed);
    float cos_camera = -dot(d, u_camera_backward);
    float image_distance = u_image_size.y / (2.0 * u_tan_half_fov.y);
    vec3 camera = VCM_MODE == VCM_MODE_PT ? vec3(0.0)
                : mis_camera_start(image_distance * image_distance / (cos_camera * cos_camera * cos_camera));
    vec3 throughput = vec3(1.0);
    // Per technique: lights hit, next-event estimation, connections, merging.
    vec3 emission = vec3(0.0), light_sample = vec3(0.0), connection = vec3(0.0), merging = vec3(0.0);
    bool specular_path = true;
    for (int segments = 1; segments <= u_max_segments; ++segments) {
        vec4 hit;
        int prim = closest_hit(o, d, hit);
        if (prim < 0) break;
        vec3 n;
        vec3 p = surface_point(prim, o, d, hit, n);
        float cos_in = abs(dot(n, d));
        camera = mis_arrive(camera, distance(o, p), cos_in, true);
        int mat = primitive_material(prim);
        Bsdf bsdf = material_bsdf(mat);
        if (bsdf.kind == MAT_EMITTER) {
            // Seen directly, a light is this technique's alone; light tracing
            // and photon mapping see it only through mirrors and glass.
            float w = 1.0;
            int l = primitive_light(prim);
            if (segments > 1) {
                if (VCM_MODE == VCM_MODE_LT || VCM_MODE == VCM_MODE_PPM) {
                    w = specular_path ? 1.0 : 0.0;
                } else if (l >= 0) {
                    AreaLight L = area_light(l);
                    float direct_pdf_a = light_texel(l, 5).y / L.area;
                    vec3 ln = L.triangles ? n : L.normal;
                    float emission_pdf_w = direct_pdf_a * max(-dot(ln, d), 0.0) / PI;
                    w = mis_emission_weight(camera, direct_pdf_a, emission_pdf_w);
                }
            }
            emission += w * throughput * emitter_seen(mat, n, d);
            break;
        }
        vec3 nf = dot(n, d) < 0.0 ? n : -n;
        uint rng = rng_init(u_seed, px, VCM_CAMERA_STREAM | uint(segments));
        if (bsdf_is_diffuse(bsdf)) {
            if (VCM_MODE == VCM_MODE_LT) break; // light tracing sees diffuse surfaces itself
            vec3 a = bsdf.color;
            float q_light = continuation(a);
            // Path tracing alone waits before its roulette (a long path is
            // cheaper than its variance); with connections the camera's
            // continuation must be the vertex's alone (src/layout.rs).
            float q = VCM_MODE == VCM_MODE_PT && segments < VCM_PT_ROULETTE_FROM
                    ? 1.0 : camera_continuation(q_light);
            vec3 brdf = bsdf_lambert(bsdf);
            if (VCM_MODE == VCM_MODE_PPM) {
                if (u_merge != 0) merging += throughput * merge(p, nf, a, q, q_light, cos_in, camera, segments);
                break;
            }
            vec3 origin = p + offset_scale(p) * nf;
            // Next-event estimation.
            if (segments + 1 <= u_max_segments && u_light_count > 0) {
                vec3 radiance, wi;
                float dist, direct_pdf_w, emission_pdf_w, cos_light;
                bool delta;
                if (sample_light(rng, p, radiance, wi, dist, direct_pdf_w, emission_pdf_w, cos_light, delta)) {
                    float cos_x = dot(nf, wi);
                    if (cos_x > 0.0 && !occluded(origin, wi, dist - 2.0 * offset_scale(p + wi * dist))) {
                        float bsdf_dir = delta ? 0.0 : q * cos_x / PI;
                        float w = VCM_MODE == VCM_MODE_PT ? 1.0 / (bsdf_dir / direct_pdf_w + 1.0)
                                : mis_light_sample_weight(camera, direct_pdf_w, emission_pdf_w, cos_light,
                                                          cos_x, bsdf_dir, q_light * cos_in / PI);
                        light_sample += w * throughput * brdf * radiance * (cos_x / direct_pdf_w);
                    }
                }
            }
            if (connections() && u_light_vertices > 0)
                connection += throughput * connect(rng, u_light_vertices, p, nf, a, q, q_light, cos_in, camera, segments);
            if (VCM_MODE == VCM_MODE_VCM && u_merge != 0)
                merging += throughput * merge(p, nf, a, q, q_light, cos_in, camera, segments);
            // Continue by Russian roulette and a cosine-distributed direction.
            if (rng_next(rng) >= q) break;
            float u1 = rng_next(rng), u2 = rng_next(rng);
            vec3 next = bsdf_sample(bsdf, frame_around(nf), -d, vec2(u1, u2)).wi;
            float cos_out = dot(nf, next);
            if (cos_out <= 0.0) break;
            camera = VCM_MODE == VCM_MODE_PT ? vec3(1.0 / (q * cos_out / PI), 0.0, 0.0)
                   : mis_scatter(camera, cos_out, q * cos_out / PI, q_light * cos_in / PI);
            throughput *= a / q;
            specular_path = false;
            o = offset_origin(p, nf, next);
            d = next;
            continue;
        }
        if (!SCENE_HAS_SPECULAR || !bsdf_is_delta(bsdf)) break;
        vec3 next_origin, next;
        specular_step(u_seed, px, segments, p, n, d, prim, bsdf, throughput, next_origin, next);
        camera = mis_scatter_specular(camera, abs(dot(n, next)));
        o = next_origin;
        d = next;
    }
    o_radiance = vec4(emission + light_sample + connection + merging, 1.0);
    o_emission = vec4(emission, 0.0);
    o_light_sample = vec4(light_sample, 0.0);
    o_connection = vec4(connection, 0.0);
    o_merging = vec4(merging, 0.0);
}
