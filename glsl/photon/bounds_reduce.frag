#version 450 core
// One level of the bounds reduction: the box of the 2 x 2 texels below.
uniform sampler2D u_min;
uniform sampler2D u_max;
layout(location = 0) out vec4 o_min;
layout(location = 1) out vec4 o_max;
void main() {
    ivec2 c = ivec2(gl_FragCoord.xy) * 2;
    ivec2 size = textureSize(u_min, 0);
    vec4 lo = vec4(3.0e38), hi = vec4(-3.0e38);
    for (int dy = 0; dy < 2; ++dy)
        for (int dx = 0; dx < 2; ++dx) {
            ivec2 t = c + ivec2(dx, dy);
            if (t.x < size.x && t.y < size.y) {
                lo = min(lo, texelFetch(u_min, t, 0));
                hi = max(hi, texelFetch(u_max, t, 0));
            }
        }
    o_min = lo;
    o_max = hi;
}
