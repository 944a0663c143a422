#version 450 core
// Ping-pong test: next = current + 1.
uniform sampler2D u_current;
layout(location = 0) out vec4 o_value;
void main() {
    o_value = texelFetch(u_current, ivec2(gl_FragCoord.xy), 0) + vec4(1.0);
}
