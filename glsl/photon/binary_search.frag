#version 450 core
// For each slot (a cell of the uniform grid, or a hash bucket), the index of
// its first photon in the sorted order (a lower bound by binary search,
// unrolled). An empty slot gets the first index of the next non-empty one, so
// slot c's photons are [first(c), first(c + 1)). One extra entry past the last
// slot holds the number of valid photons.
#include "common/addressing.glsl"

uniform isampler2D u_sorted;
uniform int u_sorted_width;
uniform int u_sorted_count;   // a power of two
uniform int u_grid_width;     // width of the grid texture
uniform int u_cell_count;

layout(location = 0) out ivec4 o_first;

void main() {
    int cell = index_of_texel(ivec2(gl_FragCoord.xy), u_grid_width);
    if (cell > u_cell_count) {
        o_first = ivec4(0);
        return;
    }
    int lo = 0;
    int hi = u_sorted_count;
    // log2(count) + 1 steps always suffice; the bound is a constant so it unrolls.
    for (int step = 0; step < 32; ++step) {
        if (lo >= hi) break;
        int mid = (lo + hi) >> 1;
        if (texelFetch(u_sorted, texel_of_index(mid, u_sorted_width), 0).x < cell) lo = mid + 1;
        else hi = mid;
    }
    o_first = ivec4(lo, 0, 0, 0);
}
