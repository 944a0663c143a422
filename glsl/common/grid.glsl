// The uniform grid over which photons are sorted or routed: cell of a point,
// or -1 outside the bounds. The bounds are closed: a point on a max face (a
// wall at the grid's edge) belongs to the last cell. src/photon/mod.rs
// (Grid::cell_of) is the twin.
uniform vec3 u_grid_min;
uniform vec3 u_grid_max;
uniform ivec3 u_grid_resolution;

int grid_cell(vec3 p) {
    vec3 f = (p - u_grid_min) / (u_grid_max - u_grid_min) * vec3(u_grid_resolution);
    if (any(lessThan(f, vec3(0.0))) || any(greaterThan(f, vec3(u_grid_resolution)))) return -1;
    ivec3 c = min(ivec3(floor(f)), u_grid_resolution - 1);
    return c.x + u_grid_resolution.x * (c.y + u_grid_resolution.y * c.z);
}
