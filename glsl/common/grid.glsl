// The grid over which photons are sorted or routed: cell of a point, or -1
// outside the bounds. The bounds are closed: a point on a max face (a wall at
// the grid's edge) belongs to the last cell. src/photon/mod.rs
// (Grid::cell_of, Grid::slot_of_cell) is the twin.
// A cell's photons live in a slot: the cell itself in a uniform grid
// (u_hash_buckets = 0), or the cell's hash bucket (section 4.4), where
// photons of other cells share the slot and readers reject them.
#include "common/random.glsl"

uniform vec3 u_grid_min;
uniform vec3 u_grid_max;
uniform ivec3 u_grid_resolution;
uniform int u_hash_buckets;   // 0: uniform grid

int grid_cell(vec3 p) {
    vec3 f = (p - u_grid_min) / (u_grid_max - u_grid_min) * vec3(u_grid_resolution);
    if (any(lessThan(f, vec3(0.0))) || any(greaterThan(f, vec3(u_grid_resolution)))) return -1;
    ivec3 c = min(ivec3(floor(f)), u_grid_resolution - 1);
    return c.x + u_grid_resolution.x * (c.y + u_grid_resolution.y * c.z);
}

// The slot of a cell: itself, or PCG(cell) mod buckets (src/photon/mod.rs hash_bucket).
int grid_slot(int cell) {
    if (u_hash_buckets == 0) return cell;
    return int(pcg_hash(uint(cell)) % uint(u_hash_buckets));
}

// The sort (or routing) key of a point: its cell's slot, or -1 outside the grid.
int grid_key(vec3 p) {
    int cell = grid_cell(p);
    return cell < 0 ? -1 : grid_slot(cell);
}
