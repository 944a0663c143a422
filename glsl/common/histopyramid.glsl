// A HistoPyramid (Ziegler, Tevs, Theobalt and Seidel 2006) read from the top
// down or the bottom up: level 0 holds counts, each level sums 2 x 2 below,
// and a texel outside a level (a side that has reached one texel) counts 0.
// photon/compact.frag walks it down to an output slot's record,
// photon/prefix_first.frag up from a slot to the counts before it.

uniform isampler2D u_pyramid;
uniform int u_top;  // the one-texel level

int count_at(int level, ivec2 t) {
    ivec2 size = textureSize(u_pyramid, level);
    if (t.x >= size.x || t.y >= size.y) return 0;
    return texelFetch(u_pyramid, t, level).x;
}
