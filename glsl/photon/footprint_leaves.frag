#version 450 core
// The footprint BVH's leaves: leaf j (node u_leaves + j of the implicit
// tree: root 1, children 2i and 2i + 1) holds footprints [j T, (j + 1) T) of
// the Morton order, and its box bounds their footprints. A leaf with none
// (past the count, or all degenerate) gets an empty box, which holds no point.
#include "common/footprint.glsl"

uniform sampler2D u_footprint0;
uniform sampler2D u_footprint1;
uniform sampler2D u_footprint2;
uniform int u_footprint_width;
uniform int u_count;
uniform int u_leaves;     // P: leaves (a power of two)
uniform int u_leaf_size;  // T
uniform int u_box_width;
uniform int u_curved;     // 1: the curved footprint, 0: the paper's ellipsoid

layout(location = 0) out vec4 o_min;
layout(location = 1) out vec4 o_max;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int leaf = px.y * u_box_width + px.x - u_leaves;
    vec3 lo = vec3(3.0e38), hi = vec3(-3.0e38);
    int first = leaf * u_leaf_size;
    int end = min(first + u_leaf_size, u_count);
    for (int i = first; i < end; ++i) {
        ivec2 t = footprint_texel(i, u_footprint_width);
        vec4 f0 = texelFetch(u_footprint0, t, 0);
        if (f0.w <= 0.0) continue;
        vec3 a = texelFetch(u_footprint1, t, 0).xyz;
        vec4 f2 = texelFetch(u_footprint2, t, 0);
        vec3 e = footprint_half_extent(a, f2.xyz, footprint_normal_axis(a, f2.xyz, f2.w), u_curved != 0);
        lo = min(lo, f0.xyz - e);
        hi = max(hi, f0.xyz + e);
    }
    o_min = vec4(lo, 0.0);
    o_max = vec4(hi, 0.0);
}
