// 1D index <-> 2D texel of a texture `width` texels wide. By default in
// integers: exact for every index a texture can hold. With FLOAT_ADDRESSING
// (`--faithful`) as the paper's convert1dto2d did on 2003 hardware, in floats:
// exact only while index < 2^24 and the division is correctly rounded (the
// host refuses larger photon counts in that mode).
#ifdef FLOAT_ADDRESSING
ivec2 texel_of_index(int index, int width) {
    float i = float(index);
    float w = float(width);
    float y = floor((i + 0.5) / w);
    return ivec2(int(i - y * w), int(y));
}

int index_of_texel(ivec2 texel, int width) {
    return int(float(texel.y) * float(width) + float(texel.x));
}
#else
ivec2 texel_of_index(int index, int width) {
    return ivec2(index % width, index / width);
}

int index_of_texel(ivec2 texel, int width) {
    return texel.y * width + texel.x;
}
#endif
