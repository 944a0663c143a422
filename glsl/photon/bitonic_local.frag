#version 450 core
// The fast sort's local pass (`--sort fused`): every step of stages
// u_stage_first..u_stage_last whose distance is below the block, for a block
// of LOCAL_BLOCK texels of one row. Each fragment reads its block's pairs,
// runs those steps in registers, and writes its own place's result: the
// first pass sorts every block (stages 2..LOCAL_BLOCK); after each later
// stage's long steps one pass finishes the stage. The direction of a
// compare-exchange is bit k of the global index i = y * width + x, as in
// the faithful pass.
#include "photon/bitonic_common.glsl"

uniform isampler2D u_pairs;
uniform int u_width;
uniform int u_stage_first;
uniform int u_stage_last;

layout(location = 0) out ivec4 o_pair;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int first_x = px.x & ~(LOCAL_BLOCK - 1);
    int row = px.y * u_width;
    ivec4 v[LOCAL_BLOCK];
    for (int p = 0; p < LOCAL_BLOCK; ++p) v[p] = texelFetch(u_pairs, ivec2(first_x + p, px.y), 0);
    for (int k = u_stage_first; k <= u_stage_last; k *= 2) {
        for (int j = min(k, LOCAL_BLOCK) / 2; j >= 1; j /= 2) {
            for (int p = 0; p < LOCAL_BLOCK; ++p) {
                int q = p ^ j;
                if (q < p) continue;
                compare_exchange(v[p], v[q], ((row + first_x + p) & k) == 0);
            }
        }
    }
    o_pair = v[px.x - first_x];
}
