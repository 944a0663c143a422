#version 450 core
// For each (index, width) in the input, the texel and the index back from it.
#include "common/addressing.glsl"
uniform isampler2D u_queries; // x = index, y = width
layout(location = 0) out ivec4 o_result;
void main() {
    ivec4 q = texelFetch(u_queries, ivec2(gl_FragCoord.xy), 0);
    ivec2 t = texel_of_index(q.x, q.y);
    o_result = ivec4(t, index_of_texel(t, q.y), 0);
}
