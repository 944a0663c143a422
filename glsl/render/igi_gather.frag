#version 450 core
// Instant global illumination (Keller 1997; Wald et al. 2002; Marques and
// Santos): the light incident at each shading point x from one batch of VPLs,
// drawn with additive blending, as incident light (not yet times x's albedo,
// so that the filters after it do not blur albedo):
//   E(x) += sum_k I_k V(x, y_k) cos(theta_x) cos(theta_y) / d^2 f(d),
// with Marques and Santos's bound f(0.8 m, 1.2 m, d): 0 below 0.8 m, 1 above
// 1.2 m and quadratic between, ((d - 0.8 m) / 0.4 m)^2 (m = u_min_distance;
// 0: unbounded).
// Shading points are the first diffuse hits of the full-resolution pixels, or
// (downsampling) of one pixel per u_scale x u_scale block. Interleaved
// sampling: pixel p samples only the VPLs of its subset, (p.x mod n) +
// n (p.y mod n), scaled by the n^2 subsets.
#include "common/scene.glsl"
#include "render/igi_shading.glsl"
#include "common/vpl_bound.glsl"

uniform sampler2D u_diffuse_position;  // full resolution, w = 1 where a hit
uniform sampler2D u_diffuse_normal;    // facing the viewer, w = material + 1
uniform sampler2D u_vpl_position;      // w = 1 where a VPL
uniform sampler2D u_vpl_normal;
uniform sampler2D u_vpl_intensity;
uniform int u_vpl_width;
uniform int u_first;                   // this batch: VPLs [u_first, u_end)
uniform int u_end;
uniform int u_scale;                   // downsampling factor (1: none)
uniform int u_interleave;              // n: n x n subsets (1: none)
uniform float u_min_distance;

layout(location = 0) out vec4 o_incident;

void main() {
    ivec2 q = ivec2(gl_FragCoord.xy);
    ivec2 px = shading_pixel(q, u_scale, textureSize(u_diffuse_position, 0));
    vec4 xp = texelFetch(u_diffuse_position, px, 0);
    // No hit, no light; discarded so that the first batch's occlusion query
    // counts the shading points.
    if (xp.w <= 0.0) discard;
    vec3 x = xp.xyz;
    vec3 nx = texelFetch(u_diffuse_normal, px, 0).xyz;
    int subsets = u_interleave * u_interleave;
    int subset = (q.x % u_interleave) + u_interleave * (q.y % u_interleave);
    // The first VPL of this batch in the pixel's subset.
    int k = u_first + ((subset - u_first % subsets) + subsets) % subsets;
    vec3 sum = vec3(0.0);
    for (; k < u_end; k += subsets) {
        ivec2 t = ivec2(k % u_vpl_width, k / u_vpl_width);
        vec3 y = texelFetch(u_vpl_position, t, 0).xyz;
        vec3 ny = texelFetch(u_vpl_normal, t, 0).xyz;
        vec3 to = y - x;
        float d2 = dot(to, to);
        if (!(d2 > 0.0)) continue;
        float d = sqrt(d2);
        vec3 w = to / d;
        float cos_x = dot(nx, w), cos_y = -dot(ny, w);
        if (cos_x <= 0.0 || cos_y <= 0.0) continue;
        float g = cos_x * cos_y / d2 * vpl_bound(d, u_min_distance);
        if (g <= 0.0) continue;
        // Along w from the lifted origin the ray would meet y's plane early
        // wherever it faces x's (a floor seen from the ceiling), and y's own
        // surface would block it; occluded_toward aims at y itself.
        if (occluded_toward(offset_origin(x, nx, w), y)) continue;
        sum += texelFetch(u_vpl_intensity, t, 0).rgb * g;
    }
    o_incident = vec4(sum * float(subsets), 0.0);
}
