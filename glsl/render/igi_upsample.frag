#version 450 core
// Instant global illumination's downsampling (Marques and Santos 4.2): the
// incident light computed at one pixel per u_scale x u_scale block, brought
// to full resolution by a joint bilateral filter (Kopf et al. 2007), the
// paper's equation 2: a spatial Gaussian over the 4 x 4 low-resolution
// neighbours around the pixel, times the cosine between the pixel's
// full-resolution first-hit normal and the neighbour's (no weight below 0),
// and, as the discontinuity buffer does, only neighbours whose hit lies
// within VPL_DEPTH_TOLERANCE of the pixel's eye distance off its tangent
// plane (depth guidance); where no neighbour has weight, the nearest one's light.
// Then, at every pixel, the incident light becomes reflected radiance:
// throughput x albedo / pi x E (with u_scale = 1 this is all the pass does).
#include "common/scene.glsl"
#include "render/igi_shading.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_incident;            // low (or full) resolution
uniform sampler2D u_diffuse_position;    // full resolution, w = 1 where a hit
uniform sampler2D u_diffuse_normal;      // w = material + 1
uniform sampler2D u_diffuse_throughput;
uniform int u_scale;
uniform vec3 u_eye;

layout(location = 0) out vec4 o_radiance;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_radiance = vec4(0.0);
    vec4 xn = texelFetch(u_diffuse_normal, px, 0);
    int mat = int(xn.w) - 1;
    if (texelFetch(u_diffuse_position, px, 0).w <= 0.0 || mat < 0) return;
    vec3 e;
    if (u_scale == 1) {
        e = texelFetch(u_incident, px, 0).rgb;
    } else {
        ivec2 low = textureSize(u_incident, 0);
        ivec2 full = textureSize(u_diffuse_position, 0);
        // The pixel's place on the low-resolution lattice (shading point of
        // block q sits at pixel q * scale + scale / 2).
        vec2 u = (vec2(px) - float(u_scale / 2)) / float(u_scale);
        ivec2 base = ivec2(floor(u)) - 1;
        vec3 x = texelFetch(u_diffuse_position, px, 0).xyz;
        float d = distance(u_eye, x);
        vec3 sum = vec3(0.0);
        float k = 0.0;
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) {
                ivec2 q = base + ivec2(i, j);
                if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, low))) continue;
                ivec2 qp = shading_pixel(q, u_scale, full);
                vec4 qx = texelFetch(u_diffuse_position, qp, 0);
                if (qx.w <= 0.0) continue;
                if (!continues_surface(x, xn.xyz, d, qx.xyz)) continue;
                float range = dot(xn.xyz, texelFetch(u_diffuse_normal, qp, 0).xyz);
                if (range <= 0.0) continue;
                vec2 off = u - vec2(q);
                float w = exp(-0.5 * dot(off, off)) * range; // sigma: one low-resolution pixel
                sum += w * texelFetch(u_incident, q, 0).rgb;
                k += w;
            }
        // No neighbour agrees (a thin object against the background, or
        // normals all turned away): the nearest shading point's light.
        if (k > 0.0) {
            e = sum / k;
        } else {
            ivec2 q = clamp(ivec2(floor(u + 0.5)), ivec2(0), low - 1);
            e = texelFetch(u_incident, q, 0).rgb;
        }
    }
    vec3 albedo = material_bsdf(mat).color; // a diffuse lobe's albedo
    o_radiance = vec4(texelFetch(u_diffuse_throughput, px, 0).rgb * albedo / PI * e, 0.0);
}
