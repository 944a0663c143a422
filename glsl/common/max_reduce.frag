#version 450 core
// One level of a maximum reduction: the largest of the 2 x 2 texels below.
uniform sampler2D u_below;
layout(location = 0) out vec4 o_max;
void main() {
    ivec2 c = ivec2(gl_FragCoord.xy) * 2;
    ivec2 size = textureSize(u_below, 0);
    vec4 hi = vec4(-3.0e38);
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            ivec2 t = c + ivec2(dx, dy);
            if (t.x < size.x && t.y < size.y) hi = max(hi, texelFetch(u_below, t, 0));
        }
    o_max = hi;
}
