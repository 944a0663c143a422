#version 450 core
// Radiosity at each eye path's first diffuse hit, or at each gather ray's
// hit: the primitive the hit records (diffuse_throughput.w), the patch of
// the side the ray sees, the leaf of its quadtree holding the hit's (u, v),
// and that tile's elements around it bilinearly (only elements that exist;
// clamped at the tile's edge).
// - At a first hit the image takes the indirect part, L = throughput x
//   (B - B_direct) / pi: direct light is the ray tracer's shadow rays.
// - At a gather hit (u_gather = 1) it takes all the hit sends back, but its
//   direct light from one shadow ray a light (a point light's exact) rather
//   than from its element: where a shadow or a contact crosses the element
//   the element's mean is wrong, and that error is most of what a gather
//   from a face near the floor it stands on reads. What the caustic deposit
//   put into the element stays: shadow rays do not carry light from
//   mirrors and glass. L = throughput x (B - B_direct + B_deposited +
//   albedo x E) / pi.
#include "common/direct_light.glsl"
#include "common/sampling.glsl"
#include "radiosity/parameterisation.glsl"
#include "radiosity/leaf.glsl"

uniform sampler2D u_diffuse_position;   // w > 0 where a first diffuse hit
uniform sampler2D u_diffuse_normal;     // facing the eye
uniform sampler2D u_diffuse_throughput; // w = the primitive hit
uniform sampler2D u_radiosity;
uniform sampler2D u_direct;
uniform sampler2D u_deposited;
uniform sampler2D u_element_position;   // w = area
uniform int u_res;
uniform int u_tile_columns;
uniform int u_gather;                   // 1: the points are a batch of gather hits
uniform uint u_seed;                    // gather hits: the eye sample's seed
uniform int u_first_ray;                // gather hits: the batch's first ray of its pixel
uniform int u_image_height;             // gather hits: ray j of the batch is row y + j x height

layout(location = 0) out vec4 o_radiance;

// The bilinear mean of B - B_direct (+ the deposit where `keep_deposit`)
// over the elements around the point's (u, v) in its leaf, or 0 where its
// side has no patch or no tile there.
vec3 solution_at(int prim, vec3 x, vec3 nf, bool keep_deposit) {
    Leaf leaf = leaf_at(prim, x, nf);
    if (leaf.tile < 0) return vec3(0.0);
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
            vec3 kept = keep_deposit ? texelFetch(u_deposited, t, 0).rgb : vec3(0.0);
            b += w * (texelFetch(u_radiosity, t, 0).rgb - texelFetch(u_direct, t, 0).rgb + kept);
            wsum += w;
        }
    }
    if (wsum > 0.0) b /= wsum;
    return max(b, vec3(0.0));
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    vec4 x = texelFetch(u_diffuse_position, px, 0);
    if (x.w <= 0.0) return;
    vec3 nf = texelFetch(u_diffuse_normal, px, 0).xyz;
    vec4 throughput = texelFetch(u_diffuse_throughput, px, 0);
    int prim = int(throughput.w);
    vec3 b = solution_at(prim, x.xyz, nf, u_gather != 0);
    if (u_gather != 0) {
        // The gather ray's own stream: its pixel and its index among them.
        int j = px.y / u_image_height;
        uvec2 pixel = uvec2(px.x, px.y - j * u_image_height);
        uint seed = pcg_hash(u_seed ^ pcg_hash(GATHER_STREAM | uint(u_first_ray + j)));
        int mat = int(texelFetch(u_diffuse_normal, px, 0).w) - 1;
        vec3 seen_from;
        vec3 e = direct_light(seed, pixel, 0, x.xyz, geometric_normal(prim, x.xyz), -nf, prim, mat,
                              true, 0, 1, 1, 1, true, seen_from);
        b += material_texel(mat, 1).rgb * e;
    }
    o_radiance = vec4(throughput.rgb * b / PI, 0.0);
}
