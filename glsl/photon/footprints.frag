#version 450 core
// The photon map of photon differentials, step 3: footprint i of the Morton
// order (common/footprint.glsl) from its photon's record and differentials
// (section 4.3's last paragraph): a photon reflected diffusely before gets
// semi-axes s Delta dp |dp|^(-3/4) (the nonlinear scaling that narrows the
// range of radii), one that has been only specular (a caustic) s_c Delta dp;
// each semi-axis is then clamped to the maximum radius. Degenerate footprints
// (a zero or non-finite area) get area 0 and are skipped by every pass after.
// With u_drop_caustics, a caustic photon's footprint gets area 0 and power 0
// and w = 1 in footprint 3 (left out: a caustic footprint map carries it).
// With u_coverage_samples > 0 the area kept is the ellipse's share on the
// photon's own surface (footprint_coverage), so that a footprint overhanging
// an edge, a corner or an occluder still spreads all its power over the
// surface instead of losing the part that hangs over.
#include "common/footprint.glsl"
#include "common/scene.glsl"

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
uniform int u_coverage_samples;   // 0: the whole ellipse counts
uniform int u_epanechnikov;       // weigh the coverage by the kernel
uniform int u_drop_caustics;      // leave out photons only specular so far

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

// The kernel-weighted share of the ellipse p + alpha a + beta b on the
// surface of `material`: at u_coverage_samples points q of a Vogel spiral
// (uniform in area), a probe from h above q's plane down its normal, 2 h
// long, must meet that material facing along the normal. It passes through
// whatever else it meets first (an occluder above the surface, such as a
// ball resting on it, hides q from the probe, not from the eye), up to
// COVERAGE_CROSSINGS surfaces. h = 0.5 rho (rho: q's distance from p) plus
// the footprint's thickness, so a surface curved away by rho^2 / 2R is met
// for radii of curvature R above rho. 1 when no probe lands (a footprint
// on a surface the probes cannot find is kept whole).
float footprint_coverage(vec3 p, vec3 a, vec3 b, float thickness, int material) {
    if (u_coverage_samples <= 0) return 1.0;
    vec3 n = normalize(cross(a, b));
    float golden = PI * (3.0 - sqrt(5.0));
    float covered = 0.0, total = 0.0;
    for (int i = 0; i < u_coverage_samples; ++i) {
        float u2 = (float(i) + 0.5) / float(u_coverage_samples);
        float phi = float(i) * golden;
        vec3 q = p + sqrt(u2) * (cos(phi) * a + sin(phi) * b);
        float w = u_epanechnikov != 0 ? 1.0 - u2 : 1.0;
        total += w;
        float h = 0.5 * distance(q, p) + thickness + 2.0 * offset_scale(q);
        vec3 o = q + n * h;
        float left = 2.0 * h;
        for (int crossing = 0; crossing < COVERAGE_CROSSINGS; ++crossing) {
            vec4 hit;
            int prim = closest_hit(o, -n, hit);
            if (prim < 0 || hit.x > left) break;
            vec3 normal;
            vec3 x = surface_point(prim, o, -n, hit, normal);
            if (primitive_material(prim) == material && abs(dot(normal, n)) >= COVERAGE_NORMAL_COS) {
                covered += w;
                break;
            }
            float step = dot(o - x, n) + 2.0 * offset_scale(x);
            o -= n * step;
            left -= step;
        }
    }
    return covered > 0.0 ? covered / total : 1.0;
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
    vec4 position = texelFetch(u_position, t, 0);
    if (!diffuse && u_drop_caustics != 0) {
        o_footprint0 = vec4(position.xyz, 0.0);
        o_footprint3 = vec4(0.0, 0.0, 0.0, 1.0);
        return;
    }
    vec3 a = semi_axis(dp1, diffuse), b = semi_axis(dp2, diffuse);
    // a x b faces the side the photon came from.
    if (dot(cross(a, b), texelFetch(u_incoming, t, 0).xyz) > 0.0) b = -b;
    float area = PI * length(cross(a, b));
    if (!(area > 0.0) || isinf(area)) area = 0.0;
    float thickness = FOOTPRINT_THICKNESS * max(length(a), length(b));
    if (area > 0.0) area *= footprint_coverage(position.xyz, a, b, thickness, int(position.w));
    o_footprint0 = vec4(position.xyz, area);
    o_footprint1 = vec4(a, diffuse ? 1.0 : 0.0);
    o_footprint2 = vec4(b, thickness);
    o_footprint3 = vec4(texelFetch(u_power, t, 0).rgb * u_power_scale, 0.0);
}
