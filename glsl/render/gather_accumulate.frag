#version 450 core
// Final gather: adds one batch of gather rays to each pixel's indirect light,
// drawn with additive blending. The radiance a gather ray brings back is the
// global map's estimate at its hit, L = throughput * albedo / pi * sum(power)
// / (pi r^2) (r as in compose.frag); with cosine-distributed rays the pixel's
// indirect light is throughput_1 * albedo_1 * mean(L) over all its rays, so
// each adds throughput_1 * albedo_1 * L / u_total_rays.
#include "common/scene.glsl"
#include "common/bsdf.glsl"
#include "common/gather_pixel.glsl"

uniform sampler2D u_gather_normal;       // the gather hits, w = material + 1
uniform sampler2D u_gather_throughput;
uniform sampler2D u_state_flux;          // the global map's estimate at each gather hit
uniform isampler2D u_state_cursor;
uniform int u_k;
uniform float u_max_radius;

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    vec3 weight;
    if (!gather_weight(px, weight)) return;
    vec3 sum = vec3(0.0);
    for (int j = 0; j < u_batch; ++j) {
        ivec2 g = gather_texel(px, j);
        int mat = int(texelFetch(u_gather_normal, g, 0).w) - 1;
        if (mat < 0) continue;
        vec4 flux = texelFetch(u_state_flux, g, 0);
        int accepted = texelFetch(u_state_cursor, g, 0).x;
        float r2 = accepted >= u_k ? flux.w : u_max_radius * u_max_radius;
        if (r2 <= 0.0) continue;
        vec3 albedo = material_bsdf(mat).color; // a diffuse lobe's albedo
        vec3 throughput = texelFetch(u_gather_throughput, g, 0).rgb;
        sum += throughput * albedo / PI * flux.rgb / (PI * r2);
    }
    o_radiance = vec4(weight * sum / u_total_rays, 0.0);
}
