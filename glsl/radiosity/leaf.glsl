// The element of the atlas that holds a point of primitive `prim` seen from
// the side its normal `nf` faces: the patch of that side, the leaf of the
// patch's quadtree holding the point's (u, v), and the (u, v) within the
// leaf's tile. Needs scene.glsl and radiosity/parameterisation.glsl, and the
// atlas uniforms below.
uniform isampler2D u_patch_of;
uniform int u_patch_of_width;
uniform isampler2D u_nodes;  // node n at (n mod TILE_ROW, n / TILE_ROW): tile t >= 0, -1 empty, -(first child + 2)

struct Leaf {
    int tile;   // -1: no patch or no tile there
    int depth;  // of the leaf in its patch's quadtree
    vec2 uv;    // within the leaf's tile, in [0, 1)^2
};

Leaf leaf_at(int prim, vec3 x, vec3 nf) {
    Leaf leaf = Leaf(-1, 0, vec2(0.0));
    int side = dot(geometric_normal(prim, x), nf) >= 0.0 ? 0 : 1;
    int k = 2 * prim + side;
    int pid = texelFetch(u_patch_of, ivec2(k % u_patch_of_width, k / u_patch_of_width), 0).x;
    if (pid < 0) return leaf;
    vec2 uv = patch_uv(prim, x);
    // Down the quadtree: children in the order (0, 0), (1, 0), (0, 1), (1, 1).
    int node = pid;
    for (int depth = 0; depth < 16; ++depth) {
        int v = texelFetch(u_nodes, ivec2(node % TILE_ROW, node / TILE_ROW), 0).x;
        if (v == -1) return leaf;
        if (v >= 0) return Leaf(v, depth, uv);
        ivec2 q = ivec2(greaterThanEqual(uv, vec2(0.5)));
        node = -v - 2 + q.x + 2 * q.y;
        uv = 2.0 * uv - vec2(q);
    }
    return leaf;
}
