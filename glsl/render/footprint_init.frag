#version 450 core
// The footprint walk's start: node 1 (the root) where the pixel has a first
// diffuse hit, 0 (done) elsewhere; nothing summed.
uniform sampler2D u_query_position;

layout(location = 0) out vec4 o_sum;
layout(location = 1) out ivec4 o_walk;

void main() {
    bool hit = texelFetch(u_query_position, ivec2(gl_FragCoord.xy), 0).w > 0.0;
    o_sum = vec4(0.0);
    o_walk = ivec4(hit ? 1 : 0, 0, 0, 0);
}
