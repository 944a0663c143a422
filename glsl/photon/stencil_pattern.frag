#version 450 core
#extension GL_ARB_shader_stencil_export : require
// Initialises the stencil of every m x m block to 0, 1, ..., m^2 - 1 (row by
// row), in one pass by stencil export.
uniform int u_block;   // m
layout(location = 0) out vec4 o_unused;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    gl_FragStencilRefARB = (px.y % u_block) * u_block + (px.x % u_block);
    o_unused = vec4(0.0);
}
