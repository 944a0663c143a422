#version 450 core
// Each tile's power, sum over its elements of value x area (luminance), of
// the residual (x: the shooter choice and convergence), the radiosity (y)
// and the last shot (z: which tiles adaptive subdivision tests): the
// reduction the chapter does by mipmapping each residual texture, as one
// loop per tile (res x res texels). Retired tiles have no area, so no power.
uniform sampler2D u_residual;
uniform sampler2D u_radiosity;
uniform sampler2D u_shot;
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
    vec3 sum = vec3(0.0);
    for (int j = 0; j < u_res; ++j) {
        for (int i = 0; i < u_res; ++i) {
            ivec2 t = base + ivec2(i, j);
            float area = texelFetch(u_element_position, t, 0).w;
            sum += area * vec3(dot(texelFetch(u_residual, t, 0).rgb, LUMINANCE),
                               dot(texelFetch(u_radiosity, t, 0).rgb, LUMINANCE),
                               dot(texelFetch(u_shot, t, 0).rgb, LUMINANCE));
        }
    }
    o_power = vec4(sum, 0.0);
}
