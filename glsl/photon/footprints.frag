#version 450 core
// The photon map of photon differentials, step 3: footprint i of the Morton
// order (common/footprint.glsl) from its photon's record and differentials
// (section 4.3's last paragraph): a photon reflected diffusely before gets
// semi-axes s Delta dp |dp|^(-3/4) (the nonlinear scaling that narrows the
// range of radii), one that has been only specular (a caustic) s_c Delta dp;
// each semi-axis is then clamped to the maximum radius. Degenerate footprints
// (a zero or non-finite area) get area 0 and are skipped by every pass after.
#include "common/footprint.glsl"

uniform isampler2D u_sorted;      // (Morton code, record) in order
uniform sampler2D u_position;     // photon records
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform sampler2D u_axis1;        // differentials at the hit
uniform sampler2D u_axis2;
uniform int u_record_width;
uniform int u_count;
uniform float u_delta;            // 2 sqrt(pi / n)
uniform float u_smoothing;        // s
uniform float u_caustic_smoothing;
uniform float u_max_radius;
uniform float u_power_scale;

layout(location = 0) out vec4 o_footprint0;
layout(location = 1) out vec4 o_footprint1;
layout(location = 2) out vec4 o_footprint2;
layout(location = 3) out vec4 o_footprint3;

vec3 semi_axis(vec3 dp, bool diffuse) {
    float len = length(dp);
    vec3 axis = diffuse ? u_smoothing * u_delta * dp * pow(len, -0.75)
                        : u_caustic_smoothing * u_delta * dp;
    float r = length(axis);
    return r > u_max_radius ? axis * (u_max_radius / r) : axis;
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int i = px.y * textureSize(u_sorted, 0).x + px.x;
    o_footprint0 = vec4(0.0);
    o_footprint1 = vec4(0.0);
    o_footprint2 = vec4(0.0);
    o_footprint3 = vec4(0.0);
    if (i >= u_count) return;
    int record = texelFetch(u_sorted, px, 0).y;
    ivec2 t = ivec2(record % u_record_width, record / u_record_width);
    vec4 axis1 = texelFetch(u_axis1, t, 0);
    vec3 dp1 = axis1.xyz, dp2 = texelFetch(u_axis2, t, 0).xyz;
    bool diffuse = axis1.w != 0.0;
    vec3 a = semi_axis(dp1, diffuse), b = semi_axis(dp2, diffuse);
    // a x b faces the side the photon came from.
    if (dot(cross(a, b), texelFetch(u_incoming, t, 0).xyz) > 0.0) b = -b;
    float area = PI * length(cross(a, b));
    if (!(area > 0.0) || isinf(area)) area = 0.0;
    float thickness = FOOTPRINT_THICKNESS * max(length(a), length(b));
    o_footprint0 = vec4(texelFetch(u_position, t, 0).xyz, area);
    o_footprint1 = vec4(a, diffuse ? 1.0 : 0.0);
    o_footprint2 = vec4(b, thickness);
    o_footprint3 = vec4(texelFetch(u_power, t, 0).rgb * u_power_scale, 0.0);
}
