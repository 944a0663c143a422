#version 450 core
// A new child tile's radiosity, residual, direct part and deposit from its parent's
// element that holds it (39.3.2; drawn over the child's region behind a
// texture barrier, reading the parent's). Each child element lies inside
// one parent element, and the four children's areas sum to the parent's, so
// the residual power is kept exactly. The shot that caused the split is
// then shot again at the children.
uniform sampler2D u_radiosity;
uniform sampler2D u_residual;
uniform sampler2D u_direct;
uniform sampler2D u_deposited;
uniform ivec2 u_child_base;   // the child's first texel
uniform ivec2 u_parent_base;  // the parent's first texel
uniform ivec2 u_quadrant;     // which quarter of the parent: (0 or 1, 0 or 1)
uniform int u_res;

layout(location = 0) out vec4 o_radiosity;
layout(location = 1) out vec4 o_residual;
layout(location = 2) out vec4 o_direct;
layout(location = 3) out vec4 o_deposited;

void main() {
    ivec2 e = ivec2(gl_FragCoord.xy) - u_child_base;
    ivec2 p = u_parent_base + (u_quadrant * u_res + e) / 2;
    o_radiosity = texelFetch(u_radiosity, p, 0);
    o_residual = texelFetch(u_residual, p, 0);
    o_direct = texelFetch(u_direct, p, 0);
    o_deposited = texelFetch(u_deposited, p, 0);
}
