// Z order (Morton order) over a power-of-two texture whose width is its
// height or twice it (`sort_texture_size`): index bits alternate x, y from
// the lowest, and a wider texture's top bit is x's. It is the order in which
// a HistoPyramid traversal visits level 0 (children (0,0), (1,0), (0,1),
// (1,1) at every level), so a pyramid over a texture laid out in it sums
// and finds indices in index order.

int spread_bits(int v) {
    v &= 0xffff;
    v = (v | (v << 8)) & 0x00ff00ff;
    v = (v | (v << 4)) & 0x0f0f0f0f;
    v = (v | (v << 2)) & 0x33333333;
    v = (v | (v << 1)) & 0x55555555;
    return v;
}

int compact_bits(int v) {
    v &= 0x55555555;
    v = (v | (v >> 1)) & 0x33333333;
    v = (v | (v >> 2)) & 0x0f0f0f0f;
    v = (v | (v >> 4)) & 0x00ff00ff;
    v = (v | (v >> 8)) & 0x0000ffff;
    return v;
}

int zindex_of_texel(ivec2 t) {
    return spread_bits(t.x) | (spread_bits(t.y) << 1);
}

ivec2 texel_of_zindex(int i) {
    return ivec2(compact_bits(i), compact_bits(i >> 1));
}
