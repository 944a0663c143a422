#version 450 core
// The counting build's cell table: for each slot (a cell of the uniform grid,
// or a hash bucket), the index of its first photon in the sorted order, the
// number of photons in the slots before it. The histogram is level 0 of a
// HistoPyramid laid out in Z order (common/zorder.glsl), so the slots before
// slot s are, at each level, the siblings that precede s's ancestor there:
// one walk up the pyramid sums them. One extra entry past the last slot holds
// the number of photons, as binary_search.frag writes it.
#include "common/addressing.glsl"
#include "common/histopyramid.glsl"
#include "common/zorder.glsl"

uniform int u_grid_width;      // width of the cell table
uniform int u_cell_count;      // slots

layout(location = 0) out ivec4 o_first;

void main() {
    int slot = index_of_texel(ivec2(gl_FragCoord.xy), u_grid_width);
    o_first = ivec4(0);
    if (slot > u_cell_count) return;
    if (slot == u_cell_count) {
        o_first.x = count_at(u_top, ivec2(0));
        return;
    }
    ivec2 t = texel_of_zindex(slot);
    int before = 0;
    for (int level = 0; level < u_top; ++level) {
        ivec2 base = (t >> level) & ~1;
        int child = ((t.x >> level) & 1) + 2 * ((t.y >> level) & 1);
        for (int k = 0; k < child; ++k) before += count_at(level, base + ivec2(k & 1, k >> 1));
    }
    o_first.x = before;
}
