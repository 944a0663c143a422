#version 450 core
// Radiosity at each eye path's first diffuse hit: the primitive the hit
// records (diffuse_throughput.w), the patch of the side the eye sees, the
// leaf of its quadtree holding the hit's (u, v), and that tile's elements
// around it bilinearly (only elements that exist; clamped at the tile's
// edge). The image takes the indirect
// part, L = throughput x (B - B_direct) / pi: direct light is the ray
// tracer's shadow rays.
#include "common/scene.glsl"
#include "common/sampling.glsl"
#include "radiosity/parameterisation.glsl"
#include "radiosity/leaf.glsl"

uniform sampler2D u_diffuse_position;   // w > 0 where a first diffuse hit
uniform sampler2D u_diffuse_normal;     // facing the eye
uniform sampler2D u_diffuse_throughput; // w = the primitive hit
uniform sampler2D u_radiosity;
uniform sampler2D u_direct;
uniform sampler2D u_element_position;   // w = area
uniform int u_res;
uniform int u_tile_columns;

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    vec4 x = texelFetch(u_diffuse_position, px, 0);
    if (x.w <= 0.0) return;
    vec3 nf = texelFetch(u_diffuse_normal, px, 0).xyz;
    vec4 throughput = texelFetch(u_diffuse_throughput, px, 0);
    int prim = int(throughput.w);
    Leaf leaf = leaf_at(prim, x.xyz, nf);
    if (leaf.tile < 0) return;
    int tile = leaf.tile, depth = leaf.depth;
    vec2 uv = leaf.uv * float(u_res) - 0.5;
    // Longitude wraps around a sphere and a cylinder (a whole patch's tile).
    int kind = int(primitive_texel(prim, 0).x);
    bool wraps = depth == 0 && (kind == PRIM_SPHERE || kind == PRIM_CYLINDER);
    ivec2 base = ivec2(tile % u_tile_columns, tile / u_tile_columns) * u_res;
    ivec2 i0 = ivec2(floor(uv));
    vec2 f = uv - vec2(i0);
    vec3 b = vec3(0.0);
    float wsum = 0.0;
    for (int j = 0; j < 2; ++j) {
        for (int i = 0; i < 2; ++i) {
            ivec2 e = i0 + ivec2(i, j);
            e.x = wraps ? (e.x + u_res) % u_res : e.x;
            e = clamp(e, ivec2(0), ivec2(u_res - 1));
            ivec2 t = base + e;
            if (texelFetch(u_element_position, t, 0).w <= 0.0) continue;
            float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
            b += w * (texelFetch(u_radiosity, t, 0).rgb - texelFetch(u_direct, t, 0).rgb);
            wsum += w;
        }
    }
    if (wsum > 0.0) b /= wsum;
    o_radiance = vec4(throughput.rgb * max(b, vec3(0.0)) / PI, 0.0);
}
