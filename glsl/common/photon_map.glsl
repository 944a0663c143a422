// Access to a built photon map, whichever build made it: the photons of a grid
// cell's slot as a range [0, count) and the i-th photon's position and power.
// ROUTED: stencil routing's m x m blocks; otherwise the sorted map. In a hash
// grid (u_hash_buckets > 0, section 4.4) the slot is the cell's bucket and
// holds other cells' photons too: photon_in_cell rejects them, and a search
// counts them as examined (the paper's collision overhead).
// src/reference/knn.rs reads the same layouts.
#include "common/addressing.glsl"
#include "common/grid.glsl"

uniform sampler2D u_map_position;  // xyz, w = 1 valid
uniform sampler2D u_map_power;     // rgb (stencil routing: redistributed; hashed: w = weight)
#ifdef ROUTED
uniform sampler2D u_map_counts;    // photons destined to each slot (x)
uniform int u_count_width;
uniform int u_block;               // m
uniform int u_blocks_per_row;
#else
uniform isampler2D u_grid_first;   // first sorted index of each slot
uniform int u_grid_width;
uniform int u_sorted_width;
#endif

// Photons stored in `cell`'s slot, and the offset that photon_texel takes.
int cell_photon_count(int cell, out int base) {
    int slot = grid_slot(cell);
#ifdef ROUTED
    base = slot;
    float destined = texelFetch(u_map_counts, texel_of_index(slot, u_count_width), 0).x;
    return min(int(destined), u_block * u_block);
#else
    base = texelFetch(u_grid_first, texel_of_index(slot, u_grid_width), 0).x;
    return texelFetch(u_grid_first, texel_of_index(slot + 1, u_grid_width), 0).x - base;
#endif
}

// Photons stored in the `run` cells from `cell` along x (a run of one is the
// cell's slot); a longer run only in a sorted uniform grid, whose slots are
// the cells, their photons one after another.
int run_photon_count(int cell, int run, out int base) {
#ifndef ROUTED
    if (run > 1) {
        base = texelFetch(u_grid_first, texel_of_index(cell, u_grid_width), 0).x;
        return texelFetch(u_grid_first, texel_of_index(cell + run, u_grid_width), 0).x - base;
    }
#endif
    return cell_photon_count(cell, base);
}

// Whether the photon at p belongs to `cell`: always in a uniform grid; in a
// hash grid only if its own cell is `cell` (the same grid_cell that keyed it).
bool photon_in_cell(vec3 p, int cell) {
    return u_hash_buckets == 0 || grid_cell(p) == cell;
}

// How many photons the stored photon at texel t of `cell` stands for: 1 in
// the sorted map; destined / kept in stencil routing, whose redistributed
// power already carries it (progressive gathers count photons with it too).
// A hashed routing keeps it per photon (power .w): a bucket's cells differ.
float photon_weight(int cell, ivec2 t) {
#ifdef ROUTED
    if (u_hash_buckets > 0) return texelFetch(u_map_power, t, 0).w;
    float destined = texelFetch(u_map_counts, texel_of_index(cell, u_count_width), 0).x;
    return destined / max(1.0, min(destined, float(u_block * u_block)));
#else
    return 1.0;
#endif
}

// The texel of the i-th photon of the slot whose `base` cell_photon_count gave.
ivec2 photon_texel(int base, int i) {
#ifdef ROUTED
    // The k-th photon of a slot sits in slot m^2 - 1 - k, row by row in its block.
    int slot = u_block * u_block - 1 - i;
    ivec2 block = texel_of_index(base, u_blocks_per_row);
    return block * u_block + ivec2(slot % u_block, slot / u_block);
#else
    return texel_of_index(base + i, u_sorted_width);
#endif
}

// The corner of the block that a range's photons fill (stencil routing's
// m x m block of the slot), for photon_texel_next.
ivec2 photon_block_origin(int base) {
#ifdef ROUTED
    return texel_of_index(base, u_blocks_per_row) * u_block;
#else
    return ivec2(0);
#endif
}

// The texel of a range's next photon, from its previous one's, without the
// divisions of photon_texel (SIMD lanes pay dearly for them): the next texel
// of the row in the sorted map; in stencil routing, whose slots count down
// row by row within the block at `origin`, the one before.
ivec2 photon_texel_next(ivec2 previous, ivec2 origin) {
#ifdef ROUTED
    return previous.x > origin.x ? ivec2(previous.x - 1, previous.y)
                                 : ivec2(origin.x + u_block - 1, previous.y - 1);
#else
    return previous.x + 1 < u_sorted_width ? ivec2(previous.x + 1, previous.y) : ivec2(0, previous.y + 1);
#endif
}
