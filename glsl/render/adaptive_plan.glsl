// Adaptive sampling (section 4.5): the plan of a pixel at one level of the
// image pyramid. Level strides halve (8, 4, 2, 1); at each level the pixels
// on its lattice that no coarser level holds are either computed (the
// estimate and final gather run on them) or interpolated bilinearly from the
// coarser lattice's corners around them: interpolated only where every corner
// sees the same material with a normal within ADAPTIVE_NORMAL_COS of the
// pixel's (the full-resolution first hits are the discontinuity buffer) and
// the corners' global light differs by at most u_threshold of its mean.
// src/render/adaptive.rs documents the levels.
#include "render/adaptive_lattice.glsl"

uniform sampler2D u_first_position;  // the pixel's first diffuse hit, w = 1 where one exists
uniform sampler2D u_first_normal;    // facing the viewer, w = material + 1
uniform sampler2D u_value;           // global light known so far, w = 1 where known
uniform int u_stride;
uniform int u_coarsest;              // 1: the first level computes its whole lattice
uniform float u_threshold;

// Plans: PLAN_NONE (not this level's pixel), PLAN_COMPUTE, PLAN_INTERPOLATE,
// PLAN_EMPTY (no diffuse hit: no global light), from src/layout.rs.

float luminance(vec3 c) { return dot(c, LUMINANCE); }

bool on_lattice(ivec2 p, int s) { return p.x % s == 0 && p.y % s == 0; }

int adaptive_plan(ivec2 p, out vec3 interpolated) {
    interpolated = vec3(0.0);
    if (!on_lattice(p, u_stride)) return PLAN_NONE;
    if (u_coarsest == 0 && on_lattice(p, 2 * u_stride)) return PLAN_NONE;
    if (texelFetch(u_first_position, p, 0).w <= 0.0) return PLAN_EMPTY;
    if (u_coarsest != 0) return PLAN_COMPUTE;
    ivec2 corners[4];
    float weights[4];
    lattice_corners(p, u_stride, textureSize(u_first_position, 0), corners, weights);
    vec4 n = texelFetch(u_first_normal, p, 0);
    float lo = 1e30, hi = -1e30;
    for (int i = 0; i < 4; ++i) {
        float w = weights[i];
        if (w == 0.0) continue;
        ivec2 c = corners[i];
        vec4 cn = texelFetch(u_first_normal, c, 0);
        if (cn.w != n.w || dot(cn.xyz, n.xyz) < ADAPTIVE_NORMAL_COS) return PLAN_COMPUTE;
        vec3 v = texelFetch(u_value, c, 0).rgb;
        lo = min(lo, luminance(v));
        hi = max(hi, luminance(v));
        interpolated += w * v;
    }
    return hi - lo > u_threshold * luminance(interpolated) ? PLAN_COMPUTE : PLAN_INTERPOLATE;
}
