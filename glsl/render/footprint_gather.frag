#version 450 core
// The radiance estimate of photon differentials (Fabianowski and Dingliana
// 2009, section 3.2): at each first diffuse hit x, the sum over every
// footprint that holds x of power x kernel / area, found by walking the
// footprint BVH. The walk is stackless over the implicit tree (root 1,
// children 2i and 2i + 1, leaves from u_leaves): descend into a box that
// holds x, else go to the next node in depth-first order (up while a right
// child, then to the right sibling); node 0 means done. At most u_budget
// nodes a pass; the state is updated in place (each fragment reads and writes
// only its own texel, a texture barrier between passes) and finished pixels
// discard, so an occlusion query counts the pixels still walking.
// Kernels: constant, 1 / A; Epanechnikov, 2 (1 - u^2) / A (u^2 the
// footprint coordinates squared, common/footprint.glsl), both integrating
// to 1 over the ellipse.
// A footprint counts only where x's normal faces the side its photon came from.
#include "common/footprint.glsl"

uniform sampler2D u_query_position;   // w > 0 where a first diffuse hit
uniform sampler2D u_query_normal;     // facing the eye
uniform sampler2D u_state_sum;        // rgb: sum, w: footprints that hold x
uniform isampler2D u_state_walk;      // node (0: done), nodes visited, footprints examined,
                                      // diffuse footprints holding x
uniform sampler2D u_box_min;
uniform sampler2D u_box_max;
uniform int u_box_width;
uniform sampler2D u_footprint0;
uniform sampler2D u_footprint1;
uniform sampler2D u_footprint2;
uniform sampler2D u_footprint3;
uniform int u_footprint_width;
uniform int u_count;
uniform int u_leaves;
uniform int u_leaf_size;
uniform int u_budget;
uniform int u_epanechnikov;
uniform int u_curved;                 // 1: the curved footprint, 0: the paper's ellipsoid

layout(location = 0) out vec4 o_sum;
layout(location = 1) out ivec4 o_walk;

ivec2 node_texel(int i) { return ivec2(i % u_box_width, i / u_box_width); }

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec4 walk = texelFetch(u_state_walk, px, 0);
    if (walk.x == 0) discard;
    vec4 sum = texelFetch(u_state_sum, px, 0);
    vec3 x = texelFetch(u_query_position, px, 0).xyz;
    vec3 nq = texelFetch(u_query_normal, px, 0).xyz;
    int node = walk.x;
    for (int step = 0; step < u_budget && node != 0; ++step) {
        walk.y += 1;
        ivec2 t = node_texel(node);
        vec3 lo = texelFetch(u_box_min, t, 0).xyz, hi = texelFetch(u_box_max, t, 0).xyz;
        bool inside = all(greaterThanEqual(x, lo)) && all(lessThanEqual(x, hi));
        if (inside && node < u_leaves) {
            node = 2 * node;
            continue;
        }
        if (inside) {
            int first = (node - u_leaves) * u_leaf_size;
            int end = min(first + u_leaf_size, u_count);
            for (int i = first; i < end; ++i) {
                ivec2 f = footprint_texel(i, u_footprint_width);
                vec4 f0 = texelFetch(u_footprint0, f, 0);
                walk.z += 1;
                if (f0.w <= 0.0) continue;
                vec4 f1 = texelFetch(u_footprint1, f, 0);
                vec3 a = f1.xyz;
                vec4 f2 = texelFetch(u_footprint2, f, 0);
                vec3 c = footprint_normal_axis(a, f2.xyz, f2.w);
                if (dot(c, nq) <= 0.0) continue;
                float u2 = footprint_distance2(x, nq, f0.xyz, a, f2.xyz, c, u_curved != 0);
                if (!(u2 <= 1.0)) continue;
                float kernel = u_epanechnikov != 0 ? 2.0 * (1.0 - u2) : 1.0;
                sum.rgb += texelFetch(u_footprint3, f, 0).rgb * (kernel / f0.w);
                sum.w += 1.0;
                if (f1.w != 0.0) walk.w += 1;
            }
        }
        // The next node in depth-first order.
        while ((node & 1) == 1) node >>= 1;
        if (node != 0) node += 1;
    }
    o_sum = sum;
    o_walk = ivec4(node, walk.yzw);
}
