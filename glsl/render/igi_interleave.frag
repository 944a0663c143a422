#version 450 core
// Instant global illumination's discontinuity buffer (Wald et al. 2002;
// Marques and Santos 4.3): each shading point's incident light becomes the
// mean over the n x n window of shading points around it (one of each VPL
// subset) that continue its surface: a first-hit normal within VPL_NORMAL_COS
// of its own, and a hit within VPL_DEPTH_TOLERANCE of its distance from the
// eye off its tangent plane. The centre always counts. Works at the
// gather's resolution (downsampled: one pixel per u_scale x u_scale block).
#include "render/igi_shading.glsl"

uniform sampler2D u_incident;          // the gather's interleaved light
uniform sampler2D u_diffuse_position;  // full resolution, w = 1 where a hit
uniform sampler2D u_diffuse_normal;
uniform vec3 u_eye;
uniform int u_scale;
uniform int u_interleave;

layout(location = 0) out vec4 o_incident;

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_incident, 0);
    ivec2 full = textureSize(u_diffuse_position, 0);
    ivec2 px = shading_pixel(q, u_scale, full);
    vec4 xp = texelFetch(u_diffuse_position, px, 0);
    vec3 centre = texelFetch(u_incident, q, 0).rgb;
    if (xp.w <= 0.0) {
        o_incident = vec4(centre, 0.0);
        return;
    }
    vec4 nx = texelFetch(u_diffuse_normal, px, 0);
    float d = distance(u_eye, xp.xyz);
    int lo = -(u_interleave - 1) / 2;
    vec3 sum = vec3(0.0);
    float n = 0.0;
    for (int j = lo; j < lo + u_interleave; ++j)
        for (int i = lo; i < lo + u_interleave; ++i) {
            ivec2 o = q + ivec2(i, j);
            if (any(lessThan(o, ivec2(0))) || any(greaterThanEqual(o, size))) continue;
            ivec2 op = shading_pixel(o, u_scale, full);
            vec4 yp = texelFetch(u_diffuse_position, op, 0);
            if (yp.w <= 0.0) continue;
            bool same = i == 0 && j == 0;
            if (!same) {
                vec3 ny = texelFetch(u_diffuse_normal, op, 0).xyz;
                if (dot(ny, nx.xyz) < VPL_NORMAL_COS) continue;
                if (!continues_surface(xp.xyz, nx.xyz, d, yp.xyz)) continue;
            }
            sum += texelFetch(u_incident, o, 0).rgb;
            n += 1.0;
        }
    o_incident = vec4(sum / n, 0.0);
}
