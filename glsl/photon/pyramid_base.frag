#version 450 core
// Level 0 of a HistoPyramid (Ziegler et al. 2006) over the photon records:
// 1 where record i (i = y * width + x of this power-of-two texture) is a stored
// photon in use inside the grid, else 0. The same test as keys.frag.
// RECORD_ORDER: record i sits at texel texel_of_zindex(i) instead, so that
// the traversal (compact.frag) visits records in index order.
#include "common/addressing.glsl"
#include "common/grid.glsl"
#ifdef RECORD_ORDER
#include "common/zorder.glsl"
#endif

uniform sampler2D u_position;
uniform sampler2D u_power;
uniform int u_level_width;
uniform int u_record_width;
uniform int u_record_count;
uniform int u_frame_height;
uniform int u_photons_used;

layout(location = 0) out ivec4 o_count;

void main() {
#ifdef RECORD_ORDER
    int i = zindex_of_texel(ivec2(gl_FragCoord.xy));
#else
    int i = index_of_texel(ivec2(gl_FragCoord.xy), u_level_width);
#endif
    o_count = ivec4(0);
    if (i >= u_record_count) return;
    ivec2 t = texel_of_index(i, u_record_width);
    int photon = (t.y % u_frame_height) * u_record_width + t.x;
    if (photon >= u_photons_used || texelFetch(u_power, t, 0).w == 0.0) return;
    if (grid_cell(texelFetch(u_position, t, 0).xyz) >= 0) o_count.x = 1;
}
