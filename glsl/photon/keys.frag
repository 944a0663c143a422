#version 450 core
// (grid slot, photon record) pairs (the slot: the cell, or its hash bucket) for the sort: one per texel of the sort
// texture. Records that are not stored photons, that belong to photons past the
// emitted count in use, or that fall outside the grid get the key INT_MAX, so
// they sort last.
#include "common/addressing.glsl"
#include "common/grid.glsl"

uniform sampler2D u_position;
uniform sampler2D u_power;
uniform int u_sort_width;     // width of the sort texture
uniform int u_record_width;   // width of the photon frames
uniform int u_record_count;   // texels in all frames
uniform int u_frame_height;
uniform int u_photons_used;   // photons with index >= this are dropped

layout(location = 0) out ivec4 o_key; // (cell, record, 0, 0)


void main() {
    int i = index_of_texel(ivec2(gl_FragCoord.xy), u_sort_width);
    o_key = ivec4(INVALID_KEY, i, 0, 0);
    if (i >= u_record_count) return;
    ivec2 t = texel_of_index(i, u_record_width);
    int photon = (t.y % u_frame_height) * u_record_width + t.x;
    if (photon >= u_photons_used) return;
    if (texelFetch(u_power, t, 0).w == 0.0) return; // not a stored photon
    int key = grid_key(texelFetch(u_position, t, 0).xyz);
    if (key >= 0) o_key.x = key;
}
