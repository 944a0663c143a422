#version 450 core
// The chosen tile's sub-elements as shooters (substructuring, 39.4): its
// res x res elements in u_sub x u_sub blocks, each one shooter with its
// elements' area-weighted normal and residual radiosity and their total
// area, at their centre weighted by residual power (by area where there is
// none). A block straddling the foot of a box on the floor then shoots from
// its lit part, outside the box: at its area centroid, under the box, its
// item buffer would see only the box's inside, and every bit of its light
// would go there. On a curved patch (u_power_centre 0) the area centroid
// stays: onto_surface puts it just past the facets along its normal.
// Row k of the output: (pos, 0), (normal, area), (B, 0).
uniform sampler2D u_residual;
uniform sampler2D u_element_position;
uniform sampler2D u_element_normal;
uniform int u_tile;
uniform int u_res;
uniform int u_tile_columns;
uniform int u_sub;
uniform int u_power_centre;           // 1: at the power-weighted centre (a flat patch)

layout(location = 0) out vec4 o_record;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int k = px.y;
    int block = u_res / u_sub;
    ivec2 base = ivec2(u_tile % u_tile_columns, u_tile / u_tile_columns) * u_res
               + ivec2(k % u_sub, k / u_sub) * block;
    vec3 pos = vec3(0.0), at_power = vec3(0.0), normal = vec3(0.0), energy = vec3(0.0);
    float area = 0.0, power = 0.0;
    for (int j = 0; j < block; ++j) {
        for (int i = 0; i < block; ++i) {
            ivec2 t = base + ivec2(i, j);
            vec4 e = texelFetch(u_element_position, t, 0);
            if (e.w <= 0.0) continue;
            vec3 b = texelFetch(u_residual, t, 0).rgb;
            float p = e.w * dot(b, LUMINANCE);
            pos += e.w * e.xyz;
            at_power += p * e.xyz;
            normal += e.w * texelFetch(u_element_normal, t, 0).xyz;
            energy += e.w * b;
            area += e.w;
            power += p;
        }
    }
    if (area <= 0.0) {
        o_record = vec4(0.0);
        return;
    }
    bool by_power = u_power_centre != 0 && power > 0.0;
    if (px.x == 0) o_record = vec4(by_power ? at_power / power : pos / area, 0.0);
    else if (px.x == 1) o_record = vec4(normalize(normal), area);
    else o_record = vec4(energy / area, 0.0);
}
