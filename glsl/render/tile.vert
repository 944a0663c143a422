#version 450 core
// One point per tile of u_tile x u_tile pixels, tile index = gl_VertexID.
// A point whose centre leaves the viewport is clipped whole, so a tile cut by
// the image's right or top edge is centred inside it instead and made large
// enough to still cover its pixels; the fragment stage discards what the
// point covers beyond the tile (v_tile), so no pixel is drawn twice in a pass.
uniform int u_tile;
uniform int u_tiles_per_row;
uniform ivec2 u_target_size;
flat out ivec4 v_tile; // x0, y0, x1, y1: the tile's pixels, ends exclusive
void main() {
    ivec2 tile = ivec2(gl_VertexID % u_tiles_per_row, gl_VertexID / u_tiles_per_row);
    ivec2 lo = tile * u_tile;
    ivec2 hi = min(lo + u_tile, u_target_size);
    v_tile = ivec4(lo, hi);
    vec2 centre = 0.5 * vec2(lo + hi);
    // A square of the larger extent, centred on the tile, covers [lo, hi).
    gl_PointSize = float(max(hi.x - lo.x, hi.y - lo.y));
    gl_Position = vec4(centre / vec2(u_target_size) * 2.0 - 1.0, 0.0, 1.0);
}
