#version 450 core
// Reflected indirect light from the footprint estimate:
// L = throughput x albedo / pi x sum (the irradiance the footprints give).
#include "common/scene.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_state_sum;
uniform sampler2D u_diffuse_normal;      // w = material + 1
uniform sampler2D u_diffuse_throughput;

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int mat = int(texelFetch(u_diffuse_normal, px, 0).w) - 1;
    vec3 l = vec3(0.0);
    if (mat >= 0) {
        vec3 albedo = material_bsdf(mat).color; // a diffuse lobe's albedo
        l = texelFetch(u_diffuse_throughput, px, 0).rgb * albedo / PI * texelFetch(u_state_sum, px, 0).rgb;
    }
    o_radiance = vec4(l, 0.0);
}
