#version 450 core
// One point per tile of u_tile x u_tile pixels, tile index = gl_VertexID.
uniform int u_tile;
uniform int u_tiles_per_row;
uniform ivec2 u_target_size;
void main() {
    ivec2 tile = ivec2(gl_VertexID % u_tiles_per_row, gl_VertexID / u_tiles_per_row);
    vec2 centre = vec2(tile * u_tile) + 0.5 * float(u_tile);
    gl_PointSize = float(u_tile);
    gl_Position = vec4(centre / vec2(u_target_size) * 2.0 - 1.0, 0.0, 1.0);
}
