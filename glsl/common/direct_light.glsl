// Direct light at a diffuse hit by shadow rays (stratified over each area
// light, a parallelogram or the emissive triangles of an OBJ group sampled by
// area; one ray per point light), and the radiance of an emitter seen.
// render/direct.frag (a pass per depth and shadow batch) and the fused
// render/eye_path.frag share it, with the same random streams.
#include "common/scene.glsl"
#include "common/random.glsl"
#include "common/bsdf.glsl"

// The radiance an emitter (material mat, geometric normal n) sends back
// along d: one-sided, it leaves on the side of the light's normal only
// (.w = 1: the primitive's own front face, its geometric normal).
vec3 emitter_seen(int mat, vec3 n, vec3 d) {
    vec4 ln = material_texel(mat, 2);
    vec3 light_normal = ln.w != 0.0 ? n : ln.xyz;
    return dot(d, light_normal) < 0.0 ? material_texel(mat, 1).rgb : vec3(0.0);
}

// Stratified sample s of area light l (strata_x columns of strata_y rows),
// from its own random stream per pixel, depth, light and sample: the point
// q, the direction wi and distance to it from origin, and the light's
// normal there. direct_light and glossy_direct_light draw the same samples.
vec3 area_light_sample(uint seed, uvec2 px, int depth, int l, AreaLight L, int s, int strata_x,
                       int strata_y, vec3 origin, out vec3 wi, out float dist,
                       out vec3 light_normal) {
    uint rng = rng_init(seed, px, 0x40000000u | (uint(depth) << 24) | (uint(l) << 12) | uint(s));
    float su = (float(s % strata_x) + rng_next(rng)) / float(strata_x);
    float sv = (float(s / strata_x) + rng_next(rng)) / float(strata_y);
    vec3 q = area_light_point(l, L, su, sv, light_normal);
    vec3 to_light = q - origin;
    dist = length(to_light);
    wi = to_light / dist;
    return q;
}

// Irradiance-like sum for direct light at the diffuse hit p (geometric
// normal n, primitive prim, material mat) seen along d; the light reflected
// is throughput * (albedo / PI) * sum, in that order (the rounding the
// stored images were made with):
// point lights when `point_lights`, and area-light samples [begin, end) of
// `shadow_rays` (strata_x columns), weighted as 1 / shadow_rays of the whole.
// nf: the geometric normal on the side seen.
vec3 direct_light(uint seed, uvec2 px, int depth, vec3 p, vec3 n, vec3 d, int prim, int mat,
                  bool point_lights, int begin, int end, int shadow_rays, int strata_x,
                  bool light_sampling, out vec3 nf) {
    nf = dot(n, d) < 0.0 ? n : -n; // one BRDF on both sides: shade the side seen
    // Shading normal (vertex normals) on the side seen: it weighs the light
    // by |cos| to it, while the geometric nf decides which side the light
    // must be on and moves the shadow ray's origin.
    bool shaded = has_shading_normal(prim);
    vec3 nsf = nf;
    if (shaded) nsf = shading_normal(prim, p, n) * (dot(n, d) < 0.0 ? 1.0 : -1.0);
    vec3 origin = p + offset_scale(p) * nf;
    vec3 sum = vec3(0.0);
    int strata_y = shadow_rays / strata_x;

    for (int l = 0; l < (light_sampling ? u_light_count : 0); ++l) {
        if (light_kind_is(light_kind(l), LIGHT_POINT)) {
            if (!point_lights) continue;
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
        for (int s = begin; s < end; ++s) {
            vec3 wi, light_normal;
            float dist;
            vec3 q = area_light_sample(seed, px, depth, l, L, s, strata_x, strata_y, origin, wi,
                                       dist, light_normal);
            float cos_x = dot(nf, wi);
            float cos_l = -dot(light_normal, wi);
            if (cos_x <= 0.0 || cos_l <= 0.0) continue;
            if (occluded_toward(origin, q)) continue;
            float cos_s = shaded ? max(dot(nsf, wi), 0.0) : cos_x;
            light_sum += emitted * (cos_s * cos_l / (dist * dist));
        }
        sum += light_sum * (L.area / float(shadow_rays));
    }
    return sum;
}

// Direct light at a hit with a glossy lobe (a rough metal), by the same
// shadow rays as direct_light, each weighted by the BSDF, combined with the path's
// own BSDF sample by the balance heuristic over both strategies: N
// shadow rays a light, one BSDF sample. A shadow ray towards light point q
// adds f Le cos_s / (N p_light + p_bsdf), p_light = dist^2 / (A cos_l) per
// solid angle; the BSDF sample that meets the light adds its share by
// `glossy_emission_weight`. Point lights take their ray alone.
// f: b in its shading frame; wo: towards the viewer; nf: the geometric
// normal on wo's side (which side a light must be on, the ray's origin).
vec3 glossy_direct_light(uint seed, uvec2 px, int depth, vec3 p, vec3 nf, Bsdf b, Frame f,
                         vec3 wo, int shadow_rays, int strata_x) {
    vec3 origin = p + offset_scale(p) * nf;
    vec3 sum = vec3(0.0);
    int strata_y = shadow_rays / strata_x;
    for (int l = 0; l < u_light_count; ++l) {
        if (light_kind_is(light_kind(l), LIGHT_POINT)) {
            vec3 to_light = light_texel(l, 1).xyz - origin;
            float dist = length(to_light);
            vec3 wi = to_light / dist;
            if (dot(nf, wi) <= 0.0 || occluded(origin, wi, dist)) continue;
            sum += bsdf_eval(b, f, wo, wi) * light_texel(l, 4).rgb * (max(dot(f.n, wi), 0.0) / (dist * dist));
            continue;
        }
        vec3 emitted = light_texel(l, 4).rgb;
        AreaLight L = area_light(l);
        for (int s = 0; s < shadow_rays; ++s) {
            vec3 wi, light_normal;
            float dist;
            vec3 q = area_light_sample(seed, px, depth, l, L, s, strata_x, strata_y, origin, wi,
                                       dist, light_normal);
            float cos_l = -dot(light_normal, wi);
            if (dot(nf, wi) <= 0.0 || cos_l <= 0.0) continue;
            vec3 fr = bsdf_eval(b, f, wo, wi);
            if (fr == vec3(0.0) || occluded_toward(origin, q)) continue;
            float p_light = dist * dist / (L.area * cos_l);
            float p_bsdf = bsdf_pdf(b, f, wo, wi);
            sum += fr * emitted * (max(dot(f.n, wi), 0.0) / (float(shadow_rays) * p_light + p_bsdf));
        }
    }
    return sum;
}

// The balance heuristic's weight of a BSDF sample (pdf p_bsdf) that left a
// glossy hit and met the emitter of primitive prim at distance dist, its
// geometric normal n, along d, against the N shadow rays a light
// glossy_direct_light draws (none: weight 1).
float glossy_emission_weight(int prim, vec3 n, vec3 d, float dist, float p_bsdf, int shadow_rays) {
    int l = primitive_light(prim);
    if (l < 0 || shadow_rays == 0) return 1.0;
    AreaLight L = area_light(l);
    float cos_l = abs(dot(L.triangles ? n : L.normal, d));
    if (cos_l <= 0.0) return 1.0;
    float p_light = dist * dist / (L.area * cos_l);
    return p_bsdf / (float(shadow_rays) * p_light + p_bsdf);
}
