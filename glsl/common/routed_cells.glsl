// The cells of a hashed stencil-routing block (section 4.4): a bucket's
// m x m block holds the first m^2 photons routed to the bucket, of one or
// several cells, filling slots m^2 - 1, m^2 - 2, ... (row by row). A photon's
// cell is recomputed from its position by grid_cell, the function that keyed it.
// src/reference/photon.rs (route_hashed) is the twin. Needs grid.glsl and
// addressing.glsl.

// The texel of the k-th photon routed to block `bucket`.
ivec2 routed_slot_texel(int bucket, int k, int m, int per_row) {
    int slot = m * m - 1 - k;
    ivec2 block = texel_of_index(bucket, per_row);
    return block * m + ivec2(slot % m, slot / m);
}

// In block `bucket`, the texel of the first kept photon of `cell` (xy; x = -1
// when the bucket kept none of it) and how many of its photons it kept (z).
ivec3 cell_in_block(sampler2D routed, int bucket, int cell, int m, int per_row) {
    ivec2 first = ivec2(-1);
    int kept = 0;
    for (int k = 0; k < m * m; ++k) {
        ivec2 t = routed_slot_texel(bucket, k, m, per_row);
        vec4 p = texelFetch(routed, t, 0);
        if (p.w == 0.0) break; // slots fill in order: the rest are empty
        if (grid_cell(p.xyz) == cell) {
            if (kept == 0) first = t;
            kept += 1;
        }
    }
    return ivec3(first, kept);
}
