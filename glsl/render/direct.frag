#version 450 core
// Direct light at diffuse hits by shadow rays (stratified over each area light,
// a parallelogram or the emissive triangles of an OBJ group sampled by area;
// one ray per point light), and emitters seen along the path. Drawn with additive
// blending: one call per batch of shadow samples adds its share. It also records
// the first diffuse hit of each eye path, where the radiance estimate will add
// indirect light and caustics: an eye path ends at its diffuse hit, so each
// pixel's record is written once and the blend onto zero copies it. Later
// batches of a depth draw into the radiance target alone.
#include "common/scene.glsl"
#include "common/random.glsl"

uniform sampler2D u_hit_position;
uniform sampler2D u_hit_normal;
uniform sampler2D u_hit_throughput;
uniform sampler2D u_hit_direction;
uniform uint u_seed;
uniform int u_depth;
uniform int u_shadow_rays;   // N per area light
uniform int u_strata_x;      // N = strata_x * strata_y
uniform int u_sample_begin;  // this batch: samples [begin, end)
uniform int u_sample_end;
uniform int u_light_sampling; // 0: no shadow rays (direct light comes from photons)

layout(location = 0) out vec4 o_radiance;
layout(location = 1) out vec4 o_diffuse_position;   // xyz, w = 1 where recorded
layout(location = 2) out vec4 o_diffuse_normal;     // facing the viewer, w = material + 1
layout(location = 3) out vec4 o_diffuse_throughput; // path throughput up to the hit, w = primitive


// Where shadow sample s of area light l lands: the point q, the light's
// unit normal there, and the light's area (its pdf is 1 / area). Strata are
// (su, sv); a LIGHT_TRIANGLES light picks its triangle with su.
// A parallelogram light's corner, edges and normal, read once per pixel,
// not once per sample.
struct AreaLight { bool triangles; vec3 a, e1, e2, normal; float area; };

AreaLight area_light(int l) {
    vec4 head = light_texel(l, 0);
    AreaLight L;
    L.triangles = int(head.x) == LIGHT_TRIANGLES;
    L.a = light_texel(l, 1).xyz;
    L.e1 = light_texel(l, 2).xyz;
    L.e2 = light_texel(l, 3).xyz;
    L.normal = head.yzw;
    L.area = L.triangles ? light_texel(l, 1).z : length(cross(L.e1, L.e2));
    return L;
}

vec3 area_light_point(int l, AreaLight L, float su, float sv, out vec3 light_normal) {
    if (L.triangles) {
        int prim;
        return sample_light_triangle(l, su, sv, light_normal, prim);
    }
    light_normal = L.normal;
    return L.a + su * L.e1 + sv * L.e2;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    o_diffuse_position = vec4(0.0);
    o_diffuse_normal = vec4(0.0);
    o_diffuse_throughput = vec4(0.0);
    vec4 hp = texelFetch(u_hit_position, px, 0);
    vec4 ht = texelFetch(u_hit_throughput, px, 0);
    // Nothing to add (the blend would add zeros): discard, which skips the
    // blend's read and write of every target.
    if (hp.w < 0.0 || ht.w == 0.0) discard;
    int mat = int(hp.w);
    int kind = material_kind(mat);
    vec3 d = texelFetch(u_hit_direction, px, 0).xyz;
    vec4 hn = texelFetch(u_hit_normal, px, 0);
    vec3 n = hn.xyz;
    bool first_batch = u_sample_begin == 0;

    if (kind == MAT_EMITTER) {
        if (!first_batch) discard;
        // One-sided: radiance leaves on the side of the light's normal only
        // (.w = 1: the primitive's own front face, its geometric normal).
        vec4 ln = material_texel(mat, 2);
        vec3 light_normal = ln.w != 0.0 ? n : ln.xyz;
        if (first_batch && dot(d, light_normal) < 0.0)
            o_radiance = vec4(ht.rgb * material_texel(mat, 1).rgb, 0.0);
        return;
    }
    if (kind != MAT_DIFFUSE) discard;

    vec3 nf = dot(n, d) < 0.0 ? n : -n; // one BRDF on both sides: shade the side seen
    vec3 p = hp.xyz;
    // Shading normal (vertex normals) on the side seen: it weighs the light
    // by |cos| to it, while the geometric nf decides which side the light
    // must be on and moves the shadow ray's origin.
    int prim = int(hn.w);
    bool shaded = has_shading_normal(prim);
    vec3 nsf = nf;
    if (shaded) nsf = shading_normal(prim, p, n) * (dot(n, d) < 0.0 ? 1.0 : -1.0);
    vec3 origin = p + offset_scale(p) * nf;
    vec3 albedo = material_texel(mat, 1).rgb;
    vec3 sum = vec3(0.0);
    int strata_y = u_shadow_rays / u_strata_x;

    for (int l = 0; l < (u_light_sampling != 0 ? u_light_count : 0); ++l) {
        vec4 head = light_texel(l, 0);
        if (int(head.x) == LIGHT_POINT) {
            if (!first_batch) continue;
            vec3 a = light_texel(l, 1).xyz;
            vec3 emitted = light_texel(l, 4).rgb;
            vec3 to_light = a - origin;
            float dist = length(to_light);
            vec3 wi = to_light / dist;
            float cos_x = dot(nf, wi);
            float cos_s = shaded ? max(dot(nsf, wi), 0.0) : cos_x;
            if (cos_x > 0.0 && !occluded(origin, wi, dist))
                sum += emitted * cos_s / (dist * dist);
            continue;
        }
        vec3 emitted = light_texel(l, 4).rgb;
        vec3 light_sum = vec3(0.0);
        AreaLight L = area_light(l);
        for (int s = u_sample_begin; s < u_sample_end; ++s) {
            uint rng = rng_init(u_seed, uvec2(px),
                                0x40000000u | (uint(u_depth) << 24) | (uint(l) << 12) | uint(s));
            float su = (float(s % u_strata_x) + rng_next(rng)) / float(u_strata_x);
            float sv = (float(s / u_strata_x) + rng_next(rng)) / float(strata_y);
            vec3 light_normal;
            vec3 q = area_light_point(l, L, su, sv, light_normal);
            vec3 to_light = q - origin;
            float dist = length(to_light);
            vec3 wi = to_light / dist;
            float cos_x = dot(nf, wi);
            float cos_l = -dot(light_normal, wi);
            if (cos_x <= 0.0 || cos_l <= 0.0) continue;
            // Stop short of the light's own surface by its offset scale.
            if (occluded(origin, wi, dist - 2.0 * offset_scale(q))) continue;
            float cos_s = shaded ? max(dot(nsf, wi), 0.0) : cos_x;
            light_sum += emitted * (cos_s * cos_l / (dist * dist));
        }
        sum += light_sum * (L.area / float(u_shadow_rays));
    }
    o_radiance = vec4(ht.rgb * (albedo / PI) * sum, 0.0);
    if (first_batch) {
        o_diffuse_position = vec4(p, 1.0);
        o_diffuse_normal = vec4(nf, float(mat + 1));
        o_diffuse_throughput = vec4(ht.rgb, float(prim));
    }
}
