#version 450 core
// One photon record per vertex, drawn as a point: over its cell's m x m block
// (routing), or as one texel of the per-cell count texture (COUNT). Records
// that are not stored photons, are past the emitted count in use, or fall
// outside the grid are moved off screen.
// CELL_COUNT (hashed grids, section 4.4): a point of size 1 at the slot of
// the first photon its bucket kept of the photon's own cell (u_split = 0), or
// at texel 0 when there is none, else texel 1 (u_split = 1: lost and kept power).
// READBACK: the paper's way, records read back to the CPU and drawn from a
// vertex buffer; otherwise the vertex stage fetches them from the photon textures.
#include "common/addressing.glsl"
#include "common/grid.glsl"
#ifdef CELL_COUNT
#include "common/routed_cells.glsl"
uniform sampler2D u_routed_position;
uniform int u_route_block;      // m of the routing
uniform int u_route_per_row;    // blocks per row of the routing buffer
uniform int u_split;
#endif

uniform int u_record_width;
uniform int u_frame_height;
uniform int u_photons_used;
uniform int u_blocks_per_row;   // cells per row of the routing buffer or count texture
uniform ivec2 u_target_size;
uniform int u_block;            // m (1 when counting)

#ifdef READBACK
layout(location = 0) in vec4 a_position;
layout(location = 1) in vec4 a_power;
layout(location = 2) in vec4 a_incoming;
#else
uniform sampler2D u_position;
uniform sampler2D u_power;
uniform sampler2D u_incoming;
#endif

flat out vec4 v_position;
flat out vec4 v_power;
flat out vec4 v_incoming;

void main() {
    int record = gl_VertexID;
    ivec2 t = texel_of_index(record, u_record_width);
#ifdef READBACK
    vec4 position = a_position, power = a_power, incoming = a_incoming;
#else
    vec4 position = texelFetch(u_position, t, 0);
    vec4 power = texelFetch(u_power, t, 0);
    vec4 incoming = texelFetch(u_incoming, t, 0);
#endif
    int photon = (t.y % u_frame_height) * u_record_width + t.x;
    int cell = grid_key(position.xyz); // the slot: the cell, or its hash bucket
    gl_PointSize = float(u_block);
    v_position = vec4(position.xyz, 1.0);
    v_power = power;
    v_incoming = incoming;
    if (power.w == 0.0 || photon >= u_photons_used || cell < 0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // clipped: not drawn
        return;
    }
#ifdef CELL_COUNT
    int own = grid_cell(position.xyz);
    ivec3 found = cell_in_block(u_routed_position, cell, own, u_route_block, u_route_per_row);
    ivec2 texel = found.xy;
    if (u_split == 1) texel = ivec2(found.x < 0 ? 0 : 1, 0);
    else if (found.x < 0) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // lost: counted by the split
        return;
    }
    gl_PointSize = 1.0;
    gl_Position = vec4((vec2(texel) + 0.5) / vec2(u_target_size) * 2.0 - 1.0, 0.0, 1.0);
    return;
#endif
    ivec2 block = texel_of_index(cell, u_blocks_per_row);
    // The centre of the block: a point of even size m centred on a pixel corner
    // covers exactly the m x m pixels around it.
    vec2 centre = vec2(block * u_block) + 0.5 * float(u_block);
    gl_Position = vec4(centre / vec2(u_target_size) * 2.0 - 1.0, 0.0, 1.0);
}
