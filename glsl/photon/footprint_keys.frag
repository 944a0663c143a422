#version 450 core
// The photon map of photon differentials, step 1: each stored record's
// 30-bit Morton code (10 bits an axis over the scene's box), as (code,
// record) pairs for the bitonic sort; past the stored count, INVALID_KEY.
// The cell coordinate is floor((p - lo) * scale), scale = 1024 / extent made
// on the CPU, so that the CPU twin computes the very same codes.
uniform isampler2D u_pairs;       // compacted (0, record) pairs
uniform sampler2D u_position;     // photon records
uniform int u_record_width;
uniform int u_count;
uniform vec3 u_lo;
uniform vec3 u_scale;

layout(location = 0) out ivec4 o_key;

uint spread_bits(uint v) {
    v = (v * 0x00010001u) & 0xFF0000FFu;
    v = (v * 0x00000101u) & 0x0F00F00Fu;
    v = (v * 0x00000011u) & 0xC30C30C3u;
    v = (v * 0x00000005u) & 0x49249249u;
    return v;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int i = px.y * textureSize(u_pairs, 0).x + px.x;
    int record = texelFetch(u_pairs, px, 0).y;
    o_key = ivec4(INVALID_KEY, i, 0, 0);
    if (i >= u_count) return;
    vec3 p = texelFetch(u_position, ivec2(record % u_record_width, record / u_record_width), 0).xyz;
    uvec3 q = uvec3(clamp(floor((p - u_lo) * u_scale), vec3(0.0), vec3(1023.0)));
    uint code = (spread_bits(q.x) << 2) | (spread_bits(q.y) << 1) | spread_bits(q.z);
    o_key = ivec4(int(code), record, 0, 0);
}
