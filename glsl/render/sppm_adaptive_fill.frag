#version 450 core
// Adaptive SPPM's photon half at full resolution. Level 0: each computed
// pixel's L = tau / (pi R^2 i) from its packed state, 0 elsewhere. Levels
// 1..3 (strides 4, 2, 1): the pixels the plan interpolates at that level, from
// the coarser lattice's corners as they stand (written by the passes before;
// this pass reads no texel it writes). The plan was fixed after the pilot.
#include "common/addressing.glsl"
#include "render/adaptive_lattice.glsl"

uniform isampler2D u_slot;        // pixel -> packed texel index, -1: not computed
uniform isampler2D u_fill_level;  // the level that interpolates the pixel, -1: none
uniform sampler2D u_packed_flux;  // tau.rgb, R^2
uniform sampler2D u_packed_sums;  // direct-light sum .rgb (unused), N
uniform sampler2D u_value;        // the photon half so far (levels 1..3)
uniform int u_level;
uniform int u_stride;
uniform float u_iterations;

layout(location = 0) out vec4 o_value;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (u_level == 0) {
        vec3 l = vec3(0.0);
        int s = texelFetch(u_slot, p, 0).x;
        if (s >= 0) {
            ivec2 t = texel_of_index(s, textureSize(u_packed_flux, 0).x);
            vec4 flux = texelFetch(u_packed_flux, t, 0);
            if (texelFetch(u_packed_sums, t, 0).w > 0.0 && flux.w > 0.0)
                l = flux.rgb / (PI * flux.w * u_iterations);
        }
        o_value = vec4(l, 1.0);
        return;
    }
    if (texelFetch(u_fill_level, p, 0).x != u_level) discard;
    ivec2 corners[4];
    float weights[4];
    lattice_corners(p, u_stride, textureSize(u_value, 0), corners, weights);
    vec3 l = vec3(0.0);
    for (int i = 0; i < 4; ++i)
        if (weights[i] != 0.0) l += weights[i] * texelFetch(u_value, corners[i], 0).rgb;
    o_value = vec4(l, 1.0);
}
