#version 450 core
// The bandwidth baseline for a bitonic pass: read one (key, record) texel, write it.
// A bitonic pass reads two texels and compares; this is what it cannot beat.
uniform isampler2D u_pairs;
layout(location = 0) out ivec4 o_pair;
void main() {
    o_pair = texelFetch(u_pairs, ivec2(gl_FragCoord.xy), 0);
}
