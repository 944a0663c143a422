#version 450 core
// The chosen tile's sub-elements as shooters (substructuring, 39.4): its
// res x res elements in u_sub x u_sub blocks, each one shooter at its
// elements' area-weighted centre, normal and residual radiosity, with their
// total area. Row k of the output: (pos, 0), (normal, area), (B, 0).
uniform sampler2D u_residual;
uniform sampler2D u_element_position;
uniform sampler2D u_element_normal;
uniform int u_tile;
uniform int u_res;
uniform int u_tile_columns;
uniform int u_sub;

layout(location = 0) out vec4 o_record;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int k = px.y;
    int block = u_res / u_sub;
    ivec2 base = ivec2(u_tile % u_tile_columns, u_tile / u_tile_columns) * u_res
               + ivec2(k % u_sub, k / u_sub) * block;
    vec3 pos = vec3(0.0), normal = vec3(0.0), energy = vec3(0.0);
    float area = 0.0;
    for (int j = 0; j < block; ++j) {
        for (int i = 0; i < block; ++i) {
            ivec2 t = base + ivec2(i, j);
            vec4 e = texelFetch(u_element_position, t, 0);
            if (e.w <= 0.0) continue;
            pos += e.w * e.xyz;
            normal += e.w * texelFetch(u_element_normal, t, 0).xyz;
            energy += e.w * texelFetch(u_residual, t, 0).rgb;
            area += e.w;
        }
    }
    if (area <= 0.0) {
        o_record = vec4(0.0);
        return;
    }
    if (px.x == 0) o_record = vec4(pos / area, 0.0);
    else if (px.x == 1) o_record = vec4(normalize(normal), area);
    else o_record = vec4(energy / area, 0.0);
}
