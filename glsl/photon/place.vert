#version 450 core
// The counting build's placement, one vertex a stored photon of the
// compacted pairs (in record order): the photon takes the next free index of
// its slot, counting down the slot's texel of the histogram, so the k-th
// photon of a slot to arrive gets index first + k, and stores its pair there.
// Nothing is drawn: every vertex is moved off screen. Where vertices are
// shaded in the order they are drawn (llvmpipe: one thread, in order), each
// slot gets its photons in record order, the bitonic sort's order; elsewhere
// the order within a slot may vary.
#include "common/addressing.glsl"
#include "common/zorder.glsl"

uniform isampler2D u_pairs;       // compacted (slot, record) pairs
uniform int u_pairs_width;
uniform isampler2D u_grid_first;  // first sorted index of each slot, and one past the last
uniform int u_grid_width;
layout(r32i) uniform iimage2D u_counts;
layout(rg32i) uniform writeonly iimage2D u_sorted;
uniform int u_sorted_width;

void main() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // clipped: not drawn
    gl_PointSize = 1.0;
    ivec4 pair = texelFetch(u_pairs, texel_of_index(gl_VertexID, u_pairs_width), 0);
    if (pair.x == INVALID_KEY) return;
    int next = texelFetch(u_grid_first, texel_of_index(pair.x + 1, u_grid_width), 0).x;
    int left = imageAtomicAdd(u_counts, texel_of_zindex(pair.x), -1);
    imageStore(u_sorted, texel_of_index(next - left, u_sorted_width), pair);
}
