#version 450 core
// Each tile's residual power, sum over its elements of residual x area
// (luminance): the reduction the chapter does by mipmapping each residual
// texture, as one loop per tile (res x res texels). Retired tiles have no
// area, so no power.
uniform sampler2D u_residual;
uniform sampler2D u_element_position; // w = area
uniform int u_tiles;           // tile t at texel (t mod TILE_ROW, t / TILE_ROW)
uniform int u_res;
uniform int u_tile_columns;

layout(location = 0) out vec4 o_power;

void main() {
    int p = int(gl_FragCoord.y) * TILE_ROW + int(gl_FragCoord.x);
    o_power = vec4(0.0);
    if (p >= u_tiles) return;
    ivec2 base = ivec2(p % u_tile_columns, p / u_tile_columns) * u_res;
    float sum = 0.0;
    for (int j = 0; j < u_res; ++j) {
        for (int i = 0; i < u_res; ++i) {
            ivec2 t = base + ivec2(i, j);
            float area = texelFetch(u_element_position, t, 0).w;
            sum += dot(texelFetch(u_residual, t, 0).rgb, LUMINANCE) * area;
        }
    }
    o_power = vec4(sum, 0.0, 0.0, 0.0);
}
