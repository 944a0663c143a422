#version 450 core
// Counting pass: each photon adds 1 to its cell (additive blending on a float
// target: exact to 2^24 photons a cell), since the 8-bit stencil saturates at 255.
flat in vec4 v_position;
flat in vec4 v_power;
flat in vec4 v_incoming;
layout(location = 0) out vec4 o_count;
void main() {
    o_count = vec4(1.0, 0.0, 0.0, 0.0);
}
