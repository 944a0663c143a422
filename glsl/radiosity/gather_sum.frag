#version 450 core
// Final gather over the radiosity solution: adds one batch of gather rays to
// each pixel's indirect light, drawn with additive blending. Ray j brings
// back L_j = B / pi at its hit (lookup.frag, u_gathered at its texel).
// src/twins/radiosity.rs (gathered_sum) is the twin.
#include "common/scene.glsl"
#include "common/bsdf.glsl"
#include "common/gather_pixel.glsl"

uniform sampler2D u_gathered;            // each ray's radiance from its hit

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    vec3 weight;
    if (!gather_weight(px, weight)) return;
    vec3 sum = vec3(0.0);
    for (int j = 0; j < u_batch; ++j)
        sum += texelFetch(u_gathered, gather_texel(px, j), 0).rgb;
    o_radiance = vec4(weight * sum / u_total_rays, 0.0);
}
