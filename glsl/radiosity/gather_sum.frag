#version 450 core
// Final gather over the radiosity solution: adds one batch of gather rays to
// each pixel's indirect light, drawn with additive blending. Ray j of the
// pixel brings back L_j = B / pi at its hit (lookup.frag, texel (x, y + j *
// height) of u_gathered); the rays are cosine-distributed, so the pixel's
// indirect light is throughput_1 * albedo_1 * mean(L) over all its rays, and
// each adds throughput_1 * albedo_1 * L_j / u_total_rays.
// src/twins/radiosity.rs (gathered_sum) is the twin.
#include "common/scene.glsl"

uniform sampler2D u_diffuse_normal;      // the pixel's first diffuse hit, w = material + 1
uniform sampler2D u_diffuse_throughput;
uniform sampler2D u_gathered;            // each ray's radiance from its hit
uniform int u_batch;
uniform int u_image_height;
uniform float u_total_rays;

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    int mat1 = int(texelFetch(u_diffuse_normal, px, 0).w) - 1;
    if (mat1 < 0) return;
    vec3 sum = vec3(0.0);
    for (int j = 0; j < u_batch; ++j)
        sum += texelFetch(u_gathered, ivec2(px.x, px.y + j * u_image_height), 0).rgb;
    vec3 albedo1 = material_texel(mat1, 1).rgb;
    vec3 throughput1 = texelFetch(u_diffuse_throughput, px, 0).rgb;
    o_radiance = vec4(throughput1 * albedo1 * sum / u_total_rays, 0.0);
}
