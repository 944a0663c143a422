// The uniform grid over which photons are sorted or routed: cell of a point,
// or -1 outside the bounds. src/photon/mod.rs (Grid::cell_of) is the twin.
uniform vec3 u_grid_min;
uniform vec3 u_grid_max;
uniform ivec3 u_grid_resolution;

int grid_cell(vec3 p) {
    vec3 f = (p - u_grid_min) / (u_grid_max - u_grid_min) * vec3(u_grid_resolution);
    ivec3 c = ivec3(floor(f));
    if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, u_grid_resolution))) return -1;
    return c.x + u_grid_resolution.x * (c.y + u_grid_resolution.y * c.z);
}
