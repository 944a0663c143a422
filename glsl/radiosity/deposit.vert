#version 450 core
// Caustic light into the element atlas before the first shot: each stored
// record of the caustic photon trace, drawn as a point onto the element it
// landed in (the leaf's element holding its (u, v)), adds its reflected
// power over the element's area, rho Phi / A, to the element's radiosity,
// residual and direct part (additive blending). Shots then carry light that
// reached a diffuse surface from a mirror or glass on to other diffuse
// surfaces (L S+ D D+), which form factors, stopped by both, cannot; the
// image takes that first reflection from the caustic map instead, as it
// takes direct light from shadow rays. Records that are not stored, past
// the photons in use, or on no element are moved off screen.
#include "common/scene.glsl"
#include "common/addressing.glsl"
#include "common/sampling.glsl"
#include "radiosity/parameterisation.glsl"
#include "radiosity/leaf.glsl"

uniform sampler2D u_position;   // xyz, w = material
uniform sampler2D u_power;      // rgb arriving, w = 1 where stored
uniform sampler2D u_incoming;   // direction of travel
uniform sampler2D u_outgoing;   // w = primitive hit
uniform int u_record_width;
uniform int u_frame_height;
uniform int u_photons_used;
uniform float u_power_scale;
uniform sampler2D u_element_position; // w = area
uniform sampler2D u_albedo;
uniform int u_res;
uniform int u_tile_columns;
uniform ivec2 u_atlas_size;

flat out vec3 v_radiosity;

void main() {
    ivec2 t = texel_of_index(gl_VertexID, u_record_width);
    vec4 power = texelFetch(u_power, t, 0);
    int photon = (t.y % u_frame_height) * u_record_width + t.x;
    gl_PointSize = 1.0;
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0); // clipped: not drawn
    v_radiosity = vec3(0.0);
    if (power.w == 0.0 || photon >= u_photons_used) return;
    vec3 x = texelFetch(u_position, t, 0).xyz;
    vec3 d = texelFetch(u_incoming, t, 0).xyz;
    int prim = int(texelFetch(u_outgoing, t, 0).w);
    if (prim < 0) return;
    Leaf leaf = leaf_at(prim, x, -d);
    if (leaf.tile < 0) return;
    ivec2 e = clamp(ivec2(floor(leaf.uv * float(u_res))), ivec2(0), ivec2(u_res - 1));
    ivec2 texel = ivec2(leaf.tile % u_tile_columns, leaf.tile / u_tile_columns) * u_res + e;
    float area = texelFetch(u_element_position, texel, 0).w;
    if (area <= 0.0) return; // a triangle's texel past its diagonal, or a retired tile
    v_radiosity = texelFetch(u_albedo, texel, 0).rgb * power.rgb * u_power_scale / area;
    gl_Position = vec4((vec2(texel) + 0.5) / vec2(u_atlas_size) * 2.0 - 1.0, 0.0, 1.0);
}
