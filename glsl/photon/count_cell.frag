#version 450 core
// Hashed stencil routing's per-cell count (section 4.4): each photon adds 1
// and its power at the slot of its cell's first kept photon, or (the lost
// split) at texel 0 if its bucket kept none of its cell, else at texel 1.
flat in vec4 v_position;
flat in vec4 v_power;
flat in vec4 v_incoming;
layout(location = 0) out vec4 o_count; // count, power rgb
void main() {
    o_count = vec4(1.0, v_power.rgb);
}
