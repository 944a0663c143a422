#version 450 core
// The footprint BVH's inner nodes, one level a pass from the leaves up:
// node i's box bounds its children's, 2i and 2i + 1 (drawn by an earlier
// pass into other texels of the same textures; a texture barrier between).
uniform sampler2D u_box_min;
uniform sampler2D u_box_max;
uniform int u_box_width;

layout(location = 0) out vec4 o_min;
layout(location = 1) out vec4 o_max;

ivec2 node_texel(int i) { return ivec2(i % u_box_width, i / u_box_width); }

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int i = px.y * u_box_width + px.x;
    ivec2 l = node_texel(2 * i), r = node_texel(2 * i + 1);
    o_min = vec4(min(texelFetch(u_box_min, l, 0).xyz, texelFetch(u_box_min, r, 0).xyz), 0.0);
    o_max = vec4(max(texelFetch(u_box_max, l, 0).xyz, texelFetch(u_box_max, r, 0).xyz), 0.0);
}
