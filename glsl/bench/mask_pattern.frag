#version 450 core
// Marks (stencil := 1, by the caller's REPLACE) the pixels to be masked:
// spread evenly (index modulo 10 below u_masked_tenths, so every SIMD block
// keeps some live pixels), or contiguous (the left tenths of the image).
uniform int u_masked_tenths;
uniform int u_contiguous;
uniform int u_width;
layout(location = 0) out vec4 o_unused;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    bool masked = u_contiguous != 0 ? px.x * 10 < u_masked_tenths * u_width
                                    : (px.x + 7 * px.y) % 10 < u_masked_tenths;
    if (!masked) discard;
    o_unused = vec4(0.0);
}
