#version 450 core
// One pass of the kNN-grid radiance estimate (section 2.3, figure 6) for every
// pixel still searching: at most u_budget steps, each examining one photon or
// moving to the next cell. State lives in textures updated in place: each
// fragment reads and writes only its own texel, with a texture barrier between
// passes (GL 4.5's one defined feedback case), so pixels not drawn (finished
// tiles, masked pixels) keep their state. Finished pixels discard, so an
// occlusion query over a draw counts the pixels that were still searching.
//
// Cells are visited in concentric cubic shells around the query point's cell
// (ring r: cells at Chebyshev distance r). A photon beyond the maximum radius
// is rejected; while fewer than k are accepted, each photon is accepted and the
// radius grows to include it; after that only photons within the radius are
// accepted. After ring r, every photon closer than d_min(r), the distance from
// the query point to the faces of the box of rings 0..r, has been examined
// (Elias; faces on the grid's boundary do not count): the search ends when k
// are accepted and the radius is within d_min(r), when d_min(r) reaches the
// maximum radius, or when the box covers the grid.
// Cells that can hold no candidate (outside the grid, inside the shell, and,
// unless NO_CULL, beyond the reach: the maximum radius, or the radius once k
// are in, which only shrinks) are skipped; NO_CULL (the paper's search) spends
// a step on each skip and opens every other cell, while the default skips
// within the step, up to SKIPS_PER_STEP at a time. The candidates and their
// order are the same either way, so the result is bit for bit the same.
// VISIBILITY_TEST accepts only photons nothing blocks from the query point (a
// thin wall does not leak light), DISC_TEST only photons near its tangent
// plane; the k nearest are then the k nearest that pass.
#include "common/photon_map.glsl"
#if defined(VISIBILITY_TEST)
#include "common/visibility.glsl"
#endif

uniform sampler2D u_query_position;  // first diffuse hit, w = 1 valid
#if defined(VISIBILITY_TEST) || defined(DISC_TEST)
uniform sampler2D u_query_normal;    // facing the eye, w = material + 1
#endif
uniform sampler2D u_state_flux;      // rgb sum of accepted power, w = radius^2
uniform isampler2D u_state_cursor;   // accepted, ring, cube cursor, photon cursor
uniform isampler2D u_state_done;     // done, photons examined, steps, cells opened
uniform int u_k;
uniform float u_max_radius;
uniform int u_budget;
#ifndef ROUTED
uniform int u_cell_runs;             // 1: read a face row's cells as one range
#endif

#ifdef TILED
flat in ivec4 v_tile; // render/tile.vert: this draw's tile; a cut tile's point covers more
#endif

layout(location = 0) out vec4 o_flux;
layout(location = 1) out ivec4 o_cursor;
layout(location = 2) out ivec4 o_done;

const int SKIPS_PER_STEP = 64;

// Per axis, how far x lies outside `cell`'s box, less the slack for rounding
// (0 inside): the box's squared distance is its dot with itself.
vec3 cell_gap(ivec3 cell, vec3 x, vec3 cell_size) {
    vec3 lo = u_grid_min + vec3(cell) * cell_size;
    return max(max(lo - x, x - lo - cell_size) - CULL_SLACK * cell_size, 0.0);
}

// Moves cursor j of shell `ring` past cells that can hold no candidate;
// returns whether it moved (false: the cell at j is to be opened). One call
// skips one run: a plane, a row, or cells of a row.
bool skip_empty(inout int j, int ring, ivec3 c0, vec3 x, vec3 cell_size, float reach2) {
    int side = 2 * ring + 1;
    int plane = side * side;
    ivec3 d = ivec3(j % side, (j / side) % side, j / plane) - ring;
    ivec3 cell = c0 + d;
    // Cells outside the grid hold nothing: jump over whole planes, rows and
    // runs of them (what makes thin grids such as 250 x 1 x 250 cheap).
    if (cell.z < 0) { j = (-c0.z + ring) * plane; return true; }
    if (cell.z >= u_grid_resolution.z) { j = plane * side; return true; }
    if (cell.y < 0) { j = (d.z + ring) * plane + (-c0.y + ring) * side; return true; }
    if (cell.y >= u_grid_resolution.y) { j = (d.z + ring + 1) * plane; return true; }
    if (abs(d.y) < ring && abs(d.z) < ring && abs(d.x) < ring) { j += ring - d.x; return true; } // interior: jump to the far face
    if (cell.x < 0) { j += -cell.x; return true; }
    if (cell.x >= u_grid_resolution.x) { j = (j / side + 1) * side; return true; }
#ifndef NO_CULL
    // Beyond the reach: the cell's box (less a slack for rounding) farther
    // than it, and with it the whole plane or row when those are, or the
    // cells of the row before the first within it.
    vec3 gap = cell_gap(cell, x, cell_size);
    float gap_yz2 = gap.y * gap.y + gap.z * gap.z;
    if (gap.z * gap.z > reach2) { j = (d.z + ring + 1) * plane; return true; }
    if (gap_yz2 > reach2) { j = (j / side + 1) * side; return true; }
    if (gap.x * gap.x > reach2 - gap_yz2) {
        int row_end = (j / side + 1) * side;
        if (d.x > 0) { j = row_end; return true; }
        float reach_x = sqrt(reach2 - gap_yz2);
        int first = int(floor((x.x - reach_x - u_grid_min.x) / cell_size.x)) - 1;
        j = min(j + max(1, first - cell.x), row_end);
        return true;
    }
#endif
    return false;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
#ifdef TILED
    if (any(lessThan(px, v_tile.xy)) || any(greaterThanEqual(px, v_tile.zw))) discard;
#endif
    ivec4 done = texelFetch(u_state_done, px, 0);
    if (done.x != 0) discard;
    vec4 flux = texelFetch(u_state_flux, px, 0);
    ivec4 cursor = texelFetch(u_state_cursor, px, 0);
    vec3 x = texelFetch(u_query_position, px, 0).xyz;
#if defined(VISIBILITY_TEST) || defined(DISC_TEST)
    vec3 nf = texelFetch(u_query_normal, px, 0).xyz;
#endif
    int accepted = cursor.x, ring = cursor.y, j = cursor.z, p = cursor.w;
    int examined = done.y, steps = done.z, opened = done.w;
    float r2 = flux.w;
    float max_r2 = u_max_radius * u_max_radius;
    vec3 cell_size = (u_grid_max - u_grid_min) / vec3(u_grid_resolution);
    ivec3 c0 = clamp(ivec3(floor((x - u_grid_min) / cell_size)), ivec3(0), u_grid_resolution - 1);
    bool finished = false;

    for (int step = 0; step < u_budget; ++step) {
        steps += 1;
        int side = 2 * ring + 1;
        int plane = side * side;
        float reach2 = accepted < u_k ? max_r2 : r2;
        if (p == 0 && j < plane * side) {
#ifdef NO_CULL
            if (skip_empty(j, ring, c0, x, cell_size, reach2)) continue;
#else
            bool moved = true;
            for (int s = 0; s < SKIPS_PER_STEP && moved && j < plane * side; ++s) {
                moved = skip_empty(j, ring, c0, x, cell_size, reach2);
            }
            if (moved && j < plane * side) continue;
#endif
        }
        if (j >= plane * side) {
            // Ring done: every photon nearer than the examined box's faces is seen.
            // A face on the grid's boundary bounds nothing: no photon lies beyond.
            vec3 lo = u_grid_min + vec3(c0 - ring) * cell_size;
            vec3 hi = u_grid_min + vec3(c0 + ring + 1) * cell_size;
            const float FAR = 3.0e38;
            vec3 lo_gap = mix(x - lo, vec3(FAR), lessThanEqual(c0 - ring, ivec3(0)));
            vec3 hi_gap = mix(hi - x, vec3(FAR), greaterThanEqual(c0 + ring, u_grid_resolution - 1));
            vec3 inside = min(lo_gap, hi_gap);
            float d_min = min(inside.x, min(inside.y, inside.z));
            bool covers = all(lessThanEqual(c0 - ring, ivec3(0))) && all(greaterThanEqual(c0 + ring, u_grid_resolution - 1));
            if (covers || d_min >= u_max_radius || (accepted >= u_k && d_min >= 0.0 && r2 <= d_min * d_min)) {
                finished = true;
                break;
            }
            ring += 1;
            j = 0;
            p = 0;
            continue;
        }
        ivec3 d = ivec3(j % side, (j / side) % side, j / plane) - ring;
        ivec3 cell = c0 + d;
        // Along x, the last cell that this step's range spans: the cell itself,
        // or, in a sorted uniform grid, the end of a face row's run (below).
        int last = cell.x;
#ifndef ROUTED
        // A sorted uniform grid stores a row's cells one after another, so a
        // face row's cells (all of them on the shell) read as one range of
        // photons, in the same order as cell by cell: one step opens them all.
        if (u_cell_runs != 0 && u_hash_buckets == 0 && (abs(d.y) == ring || abs(d.z) == ring)) {
            last = min(c0.x + ring, u_grid_resolution.x - 1);
#ifndef NO_CULL
            vec2 gap_yz = cell_gap(cell, x, cell_size).yz;
            float reach_x = sqrt(max(reach2 - dot(gap_yz, gap_yz), 0.0));
            last = min(last, int(floor((x.x + reach_x - u_grid_min.x) / cell_size.x)) + 1);
#endif
            last = max(last, cell.x);
        }
#endif
        int cell_index = cell.x + u_grid_resolution.x * (cell.y + u_grid_resolution.y * cell.z);
        int base;
        int count = run_photon_count(cell_index, last - cell.x + 1, base);
        if (p == 0) opened += 1;
        if (p >= count) { j += last - cell.x + 1; p = 0; continue; }
        // The range's photons, one a step; by default in a loop of their own,
        // so the lanes of a SIMD group run this tight body, not the whole step.
        ivec2 t = photon_texel(base, p);
        ivec2 origin = photon_block_origin(base);
        while (true) {
            vec3 photon = texelFetch(u_map_position, t, 0).xyz;
            vec3 offset = photon - x;
            float dist2 = dot(offset, offset);
            // A hash bucket's photons of other cells are examined and rejected.
            bool candidate = dist2 <= max_r2 && (accepted < u_k || dist2 <= r2) && photon_in_cell(photon, cell_index);
#ifdef DISC_TEST
            // A disc, not a sphere: photons off the query's tangent plane
            // (another wall at a corner) are not its photons.
            candidate = candidate && abs(dot(offset, nf)) <= DISC_THICKNESS * u_max_radius;
#endif
#ifdef VISIBILITY_TEST
            candidate = candidate && photon_visible(x, nf, x + offset);
#endif
            if (candidate) {
                flux.rgb += texelFetch(u_map_power, t, 0).rgb;
                if (accepted < u_k) r2 = max(r2, dist2);
                accepted += 1;
            }
            p += 1;
            examined += 1;
#ifdef NO_CULL
            break;
#else
            if (p >= count || step + 1 >= u_budget) break;
            step += 1;
            steps += 1;
            t = photon_texel_next(t, origin);
#endif
        }
#ifndef NO_CULL
        // The range's last photon moves on in the same step.
        if (p >= count) { j += last - cell.x + 1; p = 0; }
#endif
    }
    o_flux = vec4(flux.rgb, r2);
    o_cursor = ivec4(accepted, ring, j, p);
    o_done = ivec4(finished ? 1 : 0, examined, steps, opened);
}
