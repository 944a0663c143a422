#version 450 core
// Adaptive sampling, one level: the first hits of the pixels to compute,
// packed into the first texels (row by row) of textures shaped like the
// direct-light pass's, so that the estimate and final gather run on a dense
// block of queries instead of a sparse lattice (a SIMD block of fragments
// costs as much for one live pixel as for all of them). Empty texels hold no
// hit, and the estimate's computation mask skips them.
#include "common/addressing.glsl"

uniform isampler2D u_order;            // packed texel -> pixel index (y * width + x), -1: none
uniform sampler2D u_first_position;
uniform sampler2D u_first_normal;
uniform sampler2D u_first_throughput;

layout(location = 0) out vec4 o_radiance;
layout(location = 1) out vec4 o_diffuse_position;
layout(location = 2) out vec4 o_diffuse_normal;
layout(location = 3) out vec4 o_diffuse_throughput;

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    o_diffuse_position = vec4(0.0);
    o_diffuse_normal = vec4(0.0);
    o_diffuse_throughput = vec4(0.0);
    int i = texelFetch(u_order, t, 0).x;
    if (i < 0) return;
    ivec2 p = texel_of_index(i, textureSize(u_first_position, 0).x);
    o_diffuse_position = texelFetch(u_first_position, p, 0);
    o_diffuse_normal = texelFetch(u_first_normal, p, 0);
    o_diffuse_throughput = texelFetch(u_first_throughput, p, 0);
}
