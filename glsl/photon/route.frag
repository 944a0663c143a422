#version 450 core
// A routed photon's record. The stencil decides which slot of the block it
// lands in; depth (0.5 against a clear of 1, test LESS) keeps a written slot
// from ever being written again, so a cell keeps its first m^2 photons even
// after the 8-bit stencil saturates.
flat in vec4 v_position;
flat in vec4 v_power;
flat in vec4 v_incoming;
layout(location = 0) out vec4 o_position; // xyz, w = 1 where a photon landed
layout(location = 1) out vec4 o_power;
layout(location = 2) out vec4 o_incoming;
void main() {
    o_position = v_position;
    o_power = vec4(v_power.rgb, 0.0);
    o_incoming = vec4(v_incoming.xyz, 0.0);
}
