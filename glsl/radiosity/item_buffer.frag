#version 450 core
// The item buffer: the patch (primitive, side) each direction from the
// shooter sees first, or -1 (mirror, glass and emitters' backs are not
// patches but still block; -2, the clear value, is no fragment at all), the
// shooter's distance from the facet's plane, and the shown side's facet
// normal (x in z; y in w, offset by 4 sign(z): shoot.frag's `item_normal`
// unpacks it). The side is the one facing the shooter. The plane, not the
// fragment's distance, so that shoot.frag can find where the facet's plane
// crosses the exact ray to a receiver: across a texel seen edge-on, the
// fragment's distance is far from the receiver's even where the texel holds
// the receiver's own plane.
uniform isampler2D u_patch_of;  // (2 prim + side) -> patch, or -1
uniform int u_patch_of_width;
uniform vec3 u_origin;

in vec3 v_world;
flat in int v_primitive;
flat in int v_side;              // item_buffer.geom: the side the facet shows
flat in vec3 v_facing;           // and its normal

layout(location = 0) out vec4 o_patch;

void main() {
    int k = 2 * v_primitive + v_side;
    int pid = texelFetch(u_patch_of, ivec2(k % u_patch_of_width, k / u_patch_of_width), 0).x;
    float s = v_facing.z >= 0.0 ? 1.0 : -1.0;
    o_patch = vec4(float(pid), max(dot(u_origin - v_world, v_facing), 0.0), v_facing.x, v_facing.y + 4.0 * s);
}
