#version 450 core
// Adaptive SPPM, once after the pilot: the state of the pixels that go on
// computing their photon half, packed into the first texels (row by row) of
// state-shaped textures, so that each later gather runs on a dense block
// (src/render/sppm_adaptive.rs). Empty texels get a zero state: no radius,
// no photons, so the largest-radius reduction skips them.
#include "common/addressing.glsl"

uniform isampler2D u_order;       // packed texel -> pixel index (y * width + x), -1: none
uniform sampler2D u_state_flux;   // tau.rgb, R^2 (full resolution)
uniform sampler2D u_state_direct; // direct-light sum .rgb, N

layout(location = 0) out vec4 o_flux;
layout(location = 1) out vec4 o_direct;

void main() {
    int i = texelFetch(u_order, ivec2(gl_FragCoord.xy), 0).x;
    o_flux = vec4(0.0);
    o_direct = vec4(0.0);
    if (i < 0) return;
    ivec2 p = texel_of_index(i, textureSize(u_state_flux, 0).x);
    o_flux = texelFetch(u_state_flux, p, 0);
    o_direct = texelFetch(u_state_direct, p, 0);
}
