#version 450 core
// Power of each stored photon scaled by destined / stored for its cell, so a
// full cell carries the power of the photons it had no room for.
// HASHED (section 4.4): a block is a bucket's, shared by cells; each kept
// photon is scaled by destined / kept of its own cell, the destined count read
// at its cell's first kept slot (count_cell.frag), and the factor kept in .w
// (the photon's weight for progressive gathers).
#include "common/addressing.glsl"
#ifdef HASHED
#include "common/grid.glsl"
#include "common/routed_cells.glsl"
uniform sampler2D u_cell_counts;
#endif

uniform sampler2D u_routed_position;
uniform sampler2D u_routed_power;
uniform sampler2D u_counts;
uniform int u_block;
uniform int u_blocks_per_row;
uniform int u_count_width;
uniform float u_power_scale;

layout(location = 0) out vec4 o_power;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_power = vec4(0.0);
    if (texelFetch(u_routed_position, px, 0).w == 0.0) return;
    int cell = index_of_texel(px / u_block, u_blocks_per_row);
#ifdef HASHED
    int own = grid_cell(texelFetch(u_routed_position, px, 0).xyz);
    ivec3 found = cell_in_block(u_routed_position, cell, own, u_block, u_blocks_per_row);
    float scale = texelFetch(u_cell_counts, found.xy, 0).x / float(found.z);
    o_power = vec4(texelFetch(u_routed_power, px, 0).rgb * scale * u_power_scale, scale);
    return;
#endif
    float destined = texelFetch(u_counts, texel_of_index(cell, u_count_width), 0).x;
    float stored = min(destined, float(u_block * u_block));
    o_power = vec4(texelFetch(u_routed_power, px, 0).rgb * (destined / stored) * u_power_scale, 0.0);
}
