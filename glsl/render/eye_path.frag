#version 450 core
// A pixel's whole eye path in one pass: the eye ray, the stochastic chain of
// delta lobes (mirror, glass, smooth metal; common/bsdf.glsl), emitters seen along it, and at its first diffuse hit every
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
    for (; depth < u_depths; ++depth) {
        vec4 hit;
        prim = closest_hit(o, d, hit);
        if (prim < 0) return; // background radiance is zero
        p = surface_point(prim, o, d, hit, n);
        mat = primitive_material(prim);
        Bsdf b = material_bsdf(mat);
        if (b.kind == MAT_EMITTER) {
            o_radiance = vec4(throughput * emitter_seen(mat, n, d), 0.0);
            return;
        }
        if (bsdf_is_diffuse(b)) {
            diffuse = true;
            break;
        }
        if (!SCENE_HAS_SPECULAR || !bsdf_is_delta(b)) return;
        vec3 next_origin, next;
        specular_step(u_seed, px, depth, p, n, d, prim, b, throughput, next_origin, next);
        o = next_origin;
        d = next;
    }
    if (!diffuse) return;
    vec3 nf;
    vec3 sum = direct_light(u_seed, px, depth, p, n, d, prim, mat, true, 0,
                            u_shadow_rays, u_shadow_rays, u_strata_x,
                            u_light_sampling != 0, nf);
    o_radiance = vec4(throughput * bsdf_lambert(material_bsdf(mat)) * sum, 0.0);
    o_diffuse_position = vec4(p, 1.0);
    o_diffuse_normal = vec4(nf, float(mat + 1));
    o_diffuse_throughput = vec4(throughput, float(prim));
}
