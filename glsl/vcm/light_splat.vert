#version 450 core
// Light tracing, part two: one point a texel of vcm/light_connect.frag's
// output, drawn where that light vertex lands (off screen where it lands
// nowhere) with its contribution, which vcm/light_splat.frag adds into the
// light image (additive blending).
#include "common/addressing.glsl"

uniform sampler2D u_contribution;
uniform sampler2D u_landing;
uniform int u_width;

flat out vec3 v_contribution;

void main() {
    gl_PointSize = 1.0;
    ivec2 texel = texel_of_index(gl_VertexID, u_width);
    vec4 landing = texelFetch(u_landing, texel, 0);
    v_contribution = texelFetch(u_contribution, texel, 0).rgb;
    gl_Position = landing.w > 0.0 ? vec4(landing.xy, 0.0, 1.0) : vec4(2.0, 2.0, 2.0, 1.0);
}
