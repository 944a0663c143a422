#version 450 core
// One pass of bitonic merge sort over (key, record) pairs: element i compares
// with i ^ j and keeps the smaller or larger by its place in the stage k.
// Ties on the key are broken by the record index, so the decision is
// antisymmetric: if i takes its partner's pair, the partner takes i's.
// The texture is 2^a x 2^b texels with i = y * width + x, so a distance or stage
// below the width is a bit of x and one at or above it a bit of y: partner and
// direction come from XOR and AND on the coordinate, with no division
// (the host passes j and k split into their x and y parts, one of them zero).
// With FLOAT_ADDRESSING (`--faithful`) the partner is found as the paper did:
// through the 1D index and convert1dto2d in floats.
#include "common/addressing.glsl"
#include "photon/bitonic_common.glsl"

uniform isampler2D u_pairs;
uniform ivec2 u_distance_xy;  // j as (j, 0) or (0, j / width)
uniform ivec2 u_stage_xy;     // k likewise (k = n gives (0, height): always ascending)
uniform int u_width;

layout(location = 0) out ivec4 o_pair;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef FLOAT_ADDRESSING
    int distance = u_distance_xy.x + u_distance_xy.y * u_width;
    ivec2 partner_px = texel_of_index(index_of_texel(px, u_width) ^ distance, u_width);
#else
    ivec2 partner_px = px ^ u_distance_xy;
#endif
    ivec4 mine = texelFetch(u_pairs, px, 0);
    ivec4 theirs = texelFetch(u_pairs, partner_px, 0);
    bool mine_less = pair_less(mine, theirs);
    bool ascending = all(equal(px & u_stage_xy, ivec2(0)));
    bool lower = all(equal(px & u_distance_xy, ivec2(0))); // i < partner
    bool keep_smaller = lower == ascending;
    o_pair = (keep_smaller == mine_less) ? mine : theirs;
}
