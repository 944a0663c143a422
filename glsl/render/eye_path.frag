#version 450 core
// A pixel's whole eye path in one pass: the eye ray, the stochastic chain of
// delta lobes (mirror, glass, smooth metal; common/bsdf.glsl) and glossy
// ones (rough metal: shadow rays weighted by the BSDF, then a sample of the
// lobe, the two combined by the balance heuristic), emitters seen along it, and at its first diffuse hit every
// shadow ray and the visible point's record. It computes what the pass per
// bounce does (eye_rays, then per depth intersect, direct and specular), with
// the same functions and random streams, so the two give the same image to
// rounding (tests/fused_eye_path.rs); `--faithful` keeps the passes. A path
// ends at its first diffuse or emitting hit, after max_specular_depth + 1
// hits, or when it leaves the scene.
#include "common/camera.glsl"
#include "common/direct_light.glsl"
#include "common/specular_step.glsl"

uniform uint u_seed;
uniform int u_depths;        // hits at most: max_specular_depth + 1
uniform int u_shadow_rays;   // N per area light
uniform int u_strata_x;      // N = strata_x * strata_y
uniform int u_light_sampling; // 0: no shadow rays (direct light comes from photons)

layout(location = 0) out vec4 o_radiance;
layout(location = 1) out vec4 o_diffuse_position;   // xyz, w = 1 where recorded
layout(location = 2) out vec4 o_diffuse_normal;     // facing the viewer, w = material + 1
layout(location = 3) out vec4 o_diffuse_throughput; // path throughput up to the hit, w = primitive

void main() {
    uvec2 px = uvec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    o_diffuse_position = vec4(0.0);
    o_diffuse_normal = vec4(0.0);
    o_diffuse_throughput = vec4(0.0);
    vec3 o = u_camera_position;
    vec3 d = eye_ray_direction(px, u_seed);
    vec3 throughput = vec3(1.0);
    // The chain up to the first diffuse hit; its light is computed after the
    // loop, once for every lane: inside it, llvmpipe would shade each depth
    // at which some lane of a SIMD group stopped, with only those lanes.
    bool diffuse = false;
    int depth = 0, prim = -1, mat = -1;
    vec3 p, n;
    // Rough metals: the light their shadow rays found, and the pdf of the
    // last glossy sample (0: the last bounce was a delta lobe, or none).
    vec3 glossy_light = vec3(0.0);
    float glossy_pdf = 0.0;
    for (; depth < u_depths; ++depth) {
        vec4 hit;
        prim = closest_hit(o, d, hit);
        if (prim < 0) break; // background radiance is zero
        p = surface_point(prim, o, d, hit, n);
        mat = primitive_material(prim);
        Bsdf b = material_bsdf(mat);
        if (b.kind == MAT_EMITTER) {
            vec3 seen = throughput * emitter_seen(mat, n, d);
            if (SCENE_HAS_GLOSSY && glossy_pdf > 0.0) {
                int rays = u_light_sampling != 0 ? u_shadow_rays : 0;
                seen *= glossy_emission_weight(prim, n, d, distance(o, p), glossy_pdf, rays);
            }
            o_radiance = vec4(seen, 0.0);
            break;
        }
        if (bsdf_is_diffuse(b)) {
            diffuse = true;
            break;
        }
        if (SCENE_HAS_GLOSSY && bsdf_lobes(b) == BSDF_GLOSSY) {
            // Direct light by shadow rays, then on along a sample of the lobe.
            bool entering = dot(n, d) < 0.0;
            vec3 nf = entering ? n : -n;
            vec3 ms = nf;
            if (has_shading_normal(prim)) ms = shading_normal(prim, p, n) * (entering ? 1.0 : -1.0);
            Frame f = frame_around(ms);
            if (u_light_sampling != 0)
                glossy_light += throughput * glossy_direct_light(u_seed, px, depth, p, nf, b, f, -d,
                                                                 u_shadow_rays, u_strata_x);
            uint rng = rng_init(u_seed, px, 0x20000000u | uint(depth));
            float u1 = rng_next(rng);
            BsdfSample s = bsdf_sample(b, f, -d, vec2(u1, rng_next(rng)));
            if (s.lobe == 0 || dot(s.wi, nf) <= 0.0) break;
            throughput *= s.weight;
            glossy_pdf = s.pdf;
            o = offset_origin(p, nf, s.wi);
            d = s.wi;
            continue;
        }
        if (!SCENE_HAS_SPECULAR || !bsdf_is_delta(b)) break;
        glossy_pdf = 0.0;
        vec3 next_origin, next;
        specular_step(u_seed, px, depth, p, n, d, prim, b, throughput, next_origin, next);
        o = next_origin;
        d = next;
    }
    if (SCENE_HAS_GLOSSY) o_radiance.rgb += glossy_light;
    if (!diffuse) return;
    vec3 nf;
    vec3 sum = direct_light(u_seed, px, depth, p, n, d, prim, mat, true, 0,
                            u_shadow_rays, u_shadow_rays, u_strata_x,
                            u_light_sampling != 0, nf);
    o_radiance = vec4(throughput * bsdf_lambert(material_bsdf(mat)) * sum, 0.0);
    if (SCENE_HAS_GLOSSY) o_radiance.rgb += glossy_light;
    o_diffuse_position = vec4(p, 1.0);
    o_diffuse_normal = vec4(nf, float(mat + 1));
    o_diffuse_throughput = vec4(throughput, float(prim));
}
