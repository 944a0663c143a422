#version 450 core
// A deliberately expensive fragment: u_iterations rounds of transcendental
// arithmetic. Drawn behind a stencil mask, its cost shows whether masked
// fragments are really skipped.
uniform int u_iterations;
layout(location = 0) out vec4 o_value;
void main() {
    vec2 p = gl_FragCoord.xy * 0.001;
    float a = p.x, b = p.y;
    for (int i = 0; i < u_iterations; ++i) {
        a = sin(a + b) * 0.5 + cos(b * 1.3);
        b = cos(a - b) * 0.7 + sin(a * 0.9);
    }
    o_value = vec4(a, b, 0.0, 1.0);
}
