#version 450 core
// The SPPM image after i iterations: L = direct sum / i + tau / (pi R^2 i)
// (adaptive SPPM: the photon half filled by sppm_adaptive_fill.frag).
uniform sampler2D u_state_flux;   // tau.rgb, R^2
uniform sampler2D u_state_direct; // direct-light sum .rgb, N
uniform float u_iterations;
uniform int u_include_direct;
uniform int u_include_indirect;
uniform int u_adaptive;           // 1: the photon half is u_indirect (adaptive SPPM's fill)
uniform sampler2D u_indirect;

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 flux = texelFetch(u_state_flux, px, 0);
    vec4 sums = texelFetch(u_state_direct, px, 0);
    vec3 l = u_include_direct != 0 ? sums.rgb / u_iterations : vec3(0.0);
    if (u_include_indirect != 0 && u_adaptive != 0)
        l += texelFetch(u_indirect, px, 0).rgb;
    else if (u_include_indirect != 0 && sums.w > 0.0 && flux.w > 0.0)
        l += flux.rgb / (PI * flux.w * u_iterations);
    o_radiance = vec4(l, 1.0);
}
