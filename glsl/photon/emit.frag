#version 450 core
// Frame 0 of the photon textures: each photon leaves a light chosen in
// proportion to its power, carrying power = light power / (photons emitted x
// probability of that light). Area lights: a uniform point and a
// cosine-distributed direction (the emissive triangles of an OBJ group: a
// triangle by area, a uniform point in it, cosine about its normal); point
// lights: an isotropic direction.
// PROJECTION_MAPS (scenes that store caustics only): lights are picked by the
// power their projection maps keep, and a direction's two uniforms are drawn
// within a kept cell (src/photon/projection.rs), the photon carrying the kept
// fraction of the light's power.
#include "common/scene.glsl"
#include "common/photon_random.glsl"
#include "common/sampling.glsl"

uniform uint u_seed;
uniform int u_emitted;   // photons emitted N
uniform int u_width;     // frame width
#ifdef PROJECTION_MAPS
// Row l: texel 0 = (cdf, probability, kept fraction, kept cells), then the
// kept cells' indices (row * resolution + column), four a texel.
uniform sampler2D u_projection;
uniform int u_projection_resolution;
#endif

layout(location = 0) out vec4 o_position; // xyz, w = material of the hit (-1: on a light)
layout(location = 1) out vec4 o_power;    // rgb arriving, w = 1 if stored here
layout(location = 2) out vec4 o_incoming; // direction of arrival, w = 1 if it goes on
layout(location = 3) out vec4 o_outgoing; // direction it leaves by, w = primitive (-1 none)

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    int index = px.y * u_width + px.x;
    o_position = vec4(0.0, 0.0, 0.0, -1.0);
    o_power = vec4(0.0);
    o_incoming = vec4(0.0);
    o_outgoing = vec4(0.0, 0.0, 0.0, -1.0);
    if (index >= u_emitted) return;
    PhotonRandom rng = photon_random_init(u_seed, px, uvec2(px), 0x10000000u);
    float pick = photon_random_next(rng);
    int l = 0;
#ifdef PROJECTION_MAPS
    while (l < u_light_count - 1 && pick >= texelFetch(u_projection, ivec2(0, l), 0).x) ++l;
    vec4 kept = texelFetch(u_projection, ivec2(0, l), 0);
    float probability = kept.y;
#else
    while (l < u_light_count - 1 && pick >= light_texel(l, 5).x) ++l;
    float probability = light_texel(l, 5).y;
#endif
    vec4 choice = light_texel(l, 5); // (cdf, probability, primitive, 0)
    int kind = light_kind(l);
    vec3 emitted = light_texel(l, 4).rgb;
    float u1 = photon_random_next(rng), u2 = photon_random_next(rng);
    float u3 = photon_random_next(rng), u4 = photon_random_next(rng);
#ifdef PROJECTION_MAPS
    {
        int count = int(kept.w);
        int c = min(int(photon_random_next(rng) * float(count)), count - 1);
        float cell = texelFetch(u_projection, ivec2(1 + c / 4, l), 0)[c % 4];
        float n = float(u_projection_resolution);
        float row = floor(cell / n);
        float column = cell - row * n;
        // The direction's uniforms, moved into the kept cell.
        if (light_kind_is(kind, LIGHT_POINT)) {
            u1 = (column + u1) / n;
            u2 = (row + u2) / n;
        } else {
            u3 = (column + u3) / n;
            u4 = (row + u4) / n;
        }
        emitted *= kept.z;
    }
#endif
    vec3 p, d, power;
    float leaving = choice.z; // the primitive the photon leaves (-1: none)
    if (light_kind_is(kind, LIGHT_POINT)) {
        p = light_texel(l, 1).xyz;
        d = sample_sphere(u1, u2);
        power = 4.0 * PI * emitted;
    } else {
        AreaLight L = area_light(l);
        vec3 normal;
        int prim;
        p = area_light_point(l, L, u1, u2, normal, prim);
        d = sample_cosine(normal, u3, u4);
        power = PI * L.area * emitted;
        if (L.triangles) leaving = float(prim);
    }
    o_position = vec4(p, -1.0);
    o_power = vec4(power / (float(u_emitted) * probability), 0.0);
    o_incoming = vec4(0.0, 0.0, 0.0, 1.0);
    o_outgoing = vec4(d, leaving);
}
