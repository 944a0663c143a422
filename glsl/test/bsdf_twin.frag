#version 450 core
// One query of the BSDF layer per texel: the GPU side of the GLSL-vs-Rust
// BSDF twins (tests/gpu/bsdf.rs). The BSDF comes from uniforms, the frame
// from u_normal; each texel holds wo, wi and u.
#include "common/bsdf.glsl"
uniform sampler2D u_wo;
uniform sampler2D u_wi;
uniform sampler2D u_u;  // xy
uniform int u_kind;
uniform vec3 u_color;
uniform vec2 u_alpha;
uniform vec3 u_eta;
uniform vec3 u_k;
uniform vec3 u_normal;
uniform int u_model;
layout(location = 0) out vec4 o_eval;   // f(wo, wi), pdf(wo, wi)
layout(location = 1) out vec4 o_sample; // wi, lobe
layout(location = 2) out vec4 o_weight; // weight, pdf
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 wo = texelFetch(u_wo, px, 0).xyz;
    vec3 wi = texelFetch(u_wi, px, 0).xyz;
    vec2 u = texelFetch(u_u, px, 0).xy;
    Bsdf b = Bsdf(u_kind, u_color, 1.0, u_alpha, u_eta, u_k, u_model);
    Frame f = frame_around(u_normal);
    o_eval = vec4(bsdf_eval(b, f, wo, wi), bsdf_pdf(b, f, wo, wi));
    BsdfSample s = bsdf_sample(b, f, wo, u);
    o_sample = vec4(s.wi, float(s.lobe));
    o_weight = vec4(s.weight, s.pdf);
}
