#version 450 core
// Instant global illumination: the virtual point lights, one texel each. The
// VPL paths were traced by the photon passes (quasi-random, Halton), and the
// records stored at their diffuse hits compacted to the first slots (the
// bitonic build's HistoPyramid); VPL i takes the pair a random permutation
// gives it (so that interleaving's subsets, k mod n^2, are random samples of
// the paths, not one Halton stratum each): its position, its
// normal facing the side the light arrived from, and its intensity
// I = power x albedo / pi, so that it lights x with
// I cos(theta_y) cos(theta_x) / d^2 (times the albedo at x over pi).
#include "common/scene.glsl"
#include "common/addressing.glsl"
#include "common/bsdf.glsl"

uniform isampler2D u_pairs;       // (cell, record) of each stored record, compacted
uniform isampler2D u_order;       // VPL slot -> its pair (a random permutation)
uniform int u_count;              // stored records
uniform sampler2D u_position;     // the VPL paths' frames: xyz, w = material
uniform sampler2D u_power;        // rgb arriving
uniform sampler2D u_incoming;     // direction of arrival
uniform sampler2D u_outgoing;     // w = primitive hit
uniform int u_record_width;

layout(location = 0) out vec4 o_position;  // xyz, w = 1 where a VPL
layout(location = 1) out vec4 o_normal;
layout(location = 2) out vec4 o_intensity; // rgb

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    o_position = vec4(0.0);
    o_normal = vec4(0.0);
    o_intensity = vec4(0.0);
    int slot = index_of_texel(t, textureSize(u_pairs, 0).x);
    if (slot >= u_count) return;
    int pair = texelFetch(u_order, t, 0).x;
    ivec2 pt = texel_of_index(pair, textureSize(u_pairs, 0).x);
    ivec2 r = texel_of_index(texelFetch(u_pairs, pt, 0).y, u_record_width);
    vec4 p = texelFetch(u_position, r, 0);
    int prim = int(texelFetch(u_outgoing, r, 0).w);
    // The geometric normal: cos(theta_y) measures the VPL's projected area
    // (its stored power already carries the shading normal's adjoint weight).
    vec3 n = geometric_normal(prim, p.xyz);
    if (dot(n, texelFetch(u_incoming, r, 0).xyz) > 0.0) n = -n;
    vec3 albedo = material_bsdf(int(p.w)).color; // a diffuse lobe's albedo
    o_position = vec4(p.xyz, 1.0);
    o_normal = vec4(n, 0.0);
    o_intensity = vec4(texelFetch(u_power, r, 0).rgb * albedo / PI, 0.0);
}
