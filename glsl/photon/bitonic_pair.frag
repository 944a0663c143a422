#version 450 core
// The fast sort's long-distance pass (`--sort fused`): two steps of bitonic
// merge sort in one pass, distances j and j / 2 of stage k (both at least
// the local block). Element i's group is the four elements that differ from
// it in those two bits: step j compare-exchanges (a, c) and (b, d), step j / 2
// (a, b) and (c, d), all ascending or all descending by bit k (k > j). Each
// fragment reads its group's four pairs and writes its own place's result:
// the same pairs two faithful passes leave there, in half the passes.
#include "photon/bitonic_common.glsl"

uniform isampler2D u_pairs;
uniform ivec2 u_distance_xy;  // j as (j, 0) or (0, j / width)
uniform ivec2 u_half_xy;      // j / 2 likewise
uniform ivec2 u_stage_xy;     // k likewise ((0, height) for k = n: ascending)

layout(location = 0) out ivec4 o_pair;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 base = px & ~(u_distance_xy | u_half_xy);
    ivec4 a = texelFetch(u_pairs, base, 0);
    ivec4 b = texelFetch(u_pairs, base | u_half_xy, 0);
    ivec4 c = texelFetch(u_pairs, base | u_distance_xy, 0);
    ivec4 d = texelFetch(u_pairs, base | u_distance_xy | u_half_xy, 0);
    bool ascending = all(equal(px & u_stage_xy, ivec2(0)));
    // Step j: (a, c) and (b, d); the lower place takes the smaller when ascending.
    compare_exchange(a, c, ascending);
    compare_exchange(b, d, ascending);
    // Step j / 2: (a, b) and (c, d).
    compare_exchange(a, b, ascending);
    compare_exchange(c, d, ascending);
    bool upper_j = any(notEqual(px & u_distance_xy, ivec2(0)));
    bool upper_h = any(notEqual(px & u_half_xy, ivec2(0)));
    o_pair = upper_j ? (upper_h ? d : c) : (upper_h ? b : a);
}
