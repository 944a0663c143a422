#version 450 core
// One HistoPyramid level: each texel sums its 2 x 2 children one mip level
// below (fewer once a side has reached one texel). The texture's base level is
// set to the level below while this one is drawn, so lod 0 reads it.
uniform isampler2D u_below;
layout(location = 0) out ivec4 o_count;
void main() {
    ivec2 c = ivec2(gl_FragCoord.xy) * 2;
    int sum = 0;
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            ivec2 t = c + ivec2(dx, dy);
            ivec2 size = textureSize(u_below, 0);
            if (t.x < size.x && t.y < size.y) sum += texelFetch(u_below, t, 0).x;
        }
    o_count = ivec4(sum, 0, 0, 0);
}
