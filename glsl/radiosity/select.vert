#version 450 core
// The next shooter by the chapter's z-buffer sort (39.2.3): one point a tile
// into a 1 x 1 target, its depth threshold / power, so the depth test keeps
// the tile of most residual power; a tile below the threshold (the far
// plane) is not drawn, so no fragment at all means converged.
uniform sampler2D u_power;   // tile t at texel (t mod TILE_ROW, t / TILE_ROW)
uniform float u_threshold;

flat out int v_patch;

void main() {
    int p = gl_VertexID;
    float power = texelFetch(u_power, ivec2(p % TILE_ROW, p / TILE_ROW), 0).x;
    float depth = power > 0.0 ? u_threshold / power : 2.0;
    gl_Position = vec4(0.0, 0.0, 2.0 * depth - 1.0, 1.0);
    gl_PointSize = 1.0;
    v_patch = p;
}
