#version 450 core
// The chapter's split test (39.3.2, after Vedel and Puech): over one tile,
// a fragment survives where the radiosity (with the shot just made) has a
// gradient discontinuity, |B(i-1) - 2 B(i) + B(i+1)| > gradient x the three
// elements' mean + floor, along u or v (luminance; elements with a
// neighbour on both sides in the tile). An occlusion query counts the
// survivors. src/reference/radiosity.rs `discontinuities` is its twin.
uniform sampler2D u_radiosity;
uniform sampler2D u_shot;
uniform sampler2D u_element_position; // w = area
uniform ivec2 u_tile_base;
uniform int u_res;
uniform float u_gradient;
uniform float u_floor;

float radiosity_at(ivec2 t) {
    return dot(texelFetch(u_radiosity, t, 0).rgb + texelFetch(u_shot, t, 0).rgb, LUMINANCE);
}

bool uneven(ivec2 t, ivec2 step) {
    if (texelFetch(u_element_position, t - step, 0).w <= 0.0
        || texelFetch(u_element_position, t + step, 0).w <= 0.0) return false;
    float a = radiosity_at(t - step), b = radiosity_at(t), c = radiosity_at(t + step);
    return abs(a - 2.0 * b + c) > u_gradient * (a + b + c) / 3.0 + u_floor;
}

void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    ivec2 e = t - u_tile_base;
    if (texelFetch(u_element_position, t, 0).w <= 0.0) discard;
    bool across_u = e.x >= 1 && e.x + 1 < u_res && uneven(t, ivec2(1, 0));
    bool across_v = e.y >= 1 && e.y + 1 < u_res && uneven(t, ivec2(0, 1));
    if (!(across_u || across_v)) discard;
}
