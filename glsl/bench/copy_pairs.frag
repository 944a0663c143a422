#version 450 core
// The floor under a pass (src/bench/copy.rs): read one integer texel, write it.
// A bitonic pass reads two (key, record) texels and compares; a stage of
// `bench throughput` reads a record or more: this is what neither can beat.
uniform isampler2D u_pairs;
layout(location = 0) out ivec4 o_pair;
void main() {
    o_pair = texelFetch(u_pairs, ivec2(gl_FragCoord.xy), 0);
}
