#version 450 core
// The image: direct light plus the radiance estimate at each eye path's first
// diffuse hit, L = throughput * albedo / pi * sum(power) / (pi r^2). r is the
// search radius once k photons are in; while fewer are (still searching, or the
// maximum radius held fewer) the whole search disc of the maximum radius.
// Works on the running state too: the progressive image of section 3.4.
#include "common/scene.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_direct;
uniform sampler2D u_diffuse_normal;      // w = material + 1
uniform sampler2D u_diffuse_throughput;
uniform sampler2D u_state_flux;
uniform isampler2D u_state_cursor;
uniform int u_k;
uniform float u_max_radius;
uniform int u_include_direct;
uniform int u_include_indirect;

layout(location = 0) out vec4 o_radiance;


void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 l = u_include_direct != 0 ? texelFetch(u_direct, px, 0).rgb : vec3(0.0);
    int mat = int(texelFetch(u_diffuse_normal, px, 0).w) - 1;
    if (mat >= 0 && u_include_indirect != 0) {
        vec4 flux = texelFetch(u_state_flux, px, 0);
        int accepted = texelFetch(u_state_cursor, px, 0).x;
        float r2 = accepted >= u_k ? flux.w : u_max_radius * u_max_radius;
        vec3 albedo = material_bsdf(mat).color; // a diffuse lobe's albedo
        vec3 throughput = texelFetch(u_diffuse_throughput, px, 0).rgb;
        if (r2 > 0.0) l += throughput * albedo / PI * flux.rgb / (PI * r2);
    }
    o_radiance = vec4(l, 1.0);
}
