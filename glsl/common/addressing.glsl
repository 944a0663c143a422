// 1D index <-> 2D texel of a texture `width` texels wide, in integers: exact for
// every index a texture can hold (float division is not; see ARCHITECTURE.md).
ivec2 texel_of_index(int index, int width) {
    return ivec2(index % width, index / width);
}

int index_of_texel(ivec2 texel, int width) {
    return texel.y * width + texel.x;
}
