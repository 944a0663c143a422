#version 450 core
// One pass of bitonic merge sort over (key, record) pairs: element i compares
// with i ^ j and keeps the smaller or larger by its place in the stage k.
// Ties on the key are broken by the record index, so the decision is
// antisymmetric: if i takes its partner's pair, the partner takes i's.
#include "common/addressing.glsl"

uniform isampler2D u_pairs;
uniform int u_width;
uniform int u_stage;     // k: the size of the bitonic sequences being merged
uniform int u_distance;  // j: the partner distance of this pass

layout(location = 0) out ivec4 o_pair;

void main() {
    int i = index_of_texel(ivec2(gl_FragCoord.xy), u_width);
    int partner = i ^ u_distance;
    ivec4 mine = texelFetch(u_pairs, ivec2(gl_FragCoord.xy), 0);
    ivec4 theirs = texelFetch(u_pairs, texel_of_index(partner, u_width), 0);
    bool mine_less = mine.x < theirs.x || (mine.x == theirs.x && mine.y < theirs.y);
    bool ascending = (i & u_stage) == 0;
    bool keep_smaller = (i < partner) == ascending;
    o_pair = (keep_smaller == mine_less) ? mine : theirs;
}
