#version 450 core
// Counts (by occlusion query) the photons of the frame just written that go
// on: live photons pass, the rest discard. When none pass, tracing stops.
uniform sampler2D u_incoming;
uniform int u_frame_row;   // first row of the frame
layout(location = 0) out vec4 o_unused;
void main() {
    if (texelFetch(u_incoming, ivec2(gl_FragCoord.xy) + ivec2(0, u_frame_row), 0).w == 0.0) discard;
    o_unused = vec4(0.0);
}
