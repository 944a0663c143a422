#version 450 core
// Stream compaction by HistoPyramid traversal: output slot i walks down from
// the top level, at each level stepping over children (in a fixed order) until
// the one holding its i-th stored record, and writes that record's
// (cell, record) pair. Slots past the count get the invalid key. The order of
// records does not matter: the sort breaks ties by record index.
// RECORD_ORDER (the counting build): level 0 holds record i at
// texel_of_zindex(i), so slots come in record order; and each slot's record
// is counted into its grid slot's texel of u_counts (a histogram laid out in
// Z order), which the counting build's prefix sums read.
#include "common/addressing.glsl"
#include "common/histopyramid.glsl"
#include "common/grid.glsl"
#ifdef RECORD_ORDER
#include "common/zorder.glsl"
layout(r32i) uniform iimage2D u_counts;
#endif

uniform sampler2D u_position;
uniform int u_record_width;
uniform int u_out_width;
uniform int u_count;              // stored records in all

layout(location = 0) out ivec4 o_pair;


void main() {
    int slot = index_of_texel(ivec2(gl_FragCoord.xy), u_out_width);
    o_pair = ivec4(INVALID_KEY, slot, 0, 0);
    if (slot >= u_count) return;
    int rest = slot;
    ivec2 t = ivec2(0);
    for (int level = u_top - 1; level >= 0; --level) {
        ivec2 base = t * 2;
        ivec2 chosen = base;
        for (int k = 0; k < 4; ++k) {
            ivec2 c = base + ivec2(k & 1, k >> 1);
            int n = count_at(level, c);
            if (rest < n) { chosen = c; break; }
            rest -= n;
        }
        t = chosen;
    }
#ifdef RECORD_ORDER
    int record = zindex_of_texel(t);
#else
    int record = index_of_texel(t, textureSize(u_pyramid, 0).x);
#endif
    vec3 p = texelFetch(u_position, texel_of_index(record, u_record_width), 0).xyz;
    int key = grid_key(p);
    o_pair = ivec4(key, record, 0, 0);
#ifdef RECORD_ORDER
    imageAtomicAdd(u_counts, texel_of_zindex(key), 1);
#endif
}
