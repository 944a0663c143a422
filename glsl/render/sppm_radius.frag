#version 450 core
// The squared radius of each pixel that has gathered photons (N > 0), else 0:
// the base of the reduction whose maximum sizes the next iterations' grid cells.
uniform sampler2D u_state_flux;   // tau.rgb, R^2
uniform sampler2D u_state_direct; // direct-light sum .rgb, N
layout(location = 0) out vec4 o_radius2;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    float n_count = texelFetch(u_state_direct, px, 0).w;
    o_radius2 = vec4(n_count > 0.0 ? texelFetch(u_state_flux, px, 0).w : 0.0);
}
