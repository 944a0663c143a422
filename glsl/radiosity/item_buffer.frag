#version 450 core
// The item buffer: the patch (primitive, side) each direction from the
// shooter sees first, or -1 (mirror, glass and emitters' backs are not
// patches but still block; -2, the clear value, is no fragment at all). The
// side is the one facing the shooter.
uniform isampler2D u_patch_of;  // (2 prim + side) -> patch, or -1
uniform int u_patch_of_width;

in vec3 v_world;
flat in int v_primitive;
flat in int v_side;              // item_buffer.geom: the side the facet shows

layout(location = 0) out vec4 o_patch;

void main() {
    int k = 2 * v_primitive + v_side;
    int pid = texelFetch(u_patch_of, ivec2(k % u_patch_of_width, k / u_patch_of_width), 0).x;
    o_patch = vec4(float(pid), 0.0, 0.0, 1.0);
}
