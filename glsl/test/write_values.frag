#version 450 core
// Writes values that are exact in binary32 and that the test recomputes:
// the pixel's coordinates, a power of two, and an integer above 2^23.
uniform float u_value;
layout(location = 0) out vec4 o_value;
void main() {
    vec2 p = floor(gl_FragCoord.xy);
    o_value = vec4(p.x, p.y, u_value, 16777215.0 - p.x);
}
