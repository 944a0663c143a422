#version 450 core
// Photon differentials (Igehy 1999; Schjoth et al. 2007; Fabianowski and
// Dingliana 2009, section 4) for one frame of the photon textures, from its
// records and the previous frame's differentials (a band of the same
// textures; a texture barrier between passes makes it visible).
// Per photon: two positional and two directional differentials, in units of
// the global spacing Delta = 2 sqrt(pi / n), so that a footprint's semi-axes
// are Delta dp. Written per record:
//   axis 1, 2: dp at this frame's hit (transferred to its surface); axis1.w
//     = 1 if the photon had been reflected diffusely before this hit;
//   state 0..2: dp and dd as the photon leaves (after the interaction);
//     axis2.w = the diffuse flag it leaves with.
// Emission: the directional differentials are an orthonormal pair about d
// (equation 8) scaled by sqrt(kept fraction / pick probability), the light's
// share of the photons and of its directions; an area light's (ours: the
// paper has point lights only) positional ones are the same pair scaled by
// sqrt(area / (4 pi p)), a footprint of pi x its area per photon. Transfer:
// Igehy's equations. Mirror and glass: reflection and refraction of the
// differentials about the normal used, with the normal's own differential on
// spheres and cylinders (flat primitives, shaded triangles included: 0). A
// random branch of probability q (glass's Fresnel choice; a diffuse bounce's
// Russian roulette) scales the differentials by 1 / sqrt(q) (section 4.2).
// Diffuse bounce: re-emission from a virtual origin v behind the hit, so that
// the new footprint's area equals the old one's (section 4.3, equation 13).
// src/twins/differentials.rs is its twin.
#include "common/scene.glsl"
#include "common/sampling.glsl"
#include "common/specular.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_position;
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform sampler2D u_outgoing;
uniform sampler2D u_axis1;
uniform sampler2D u_axis2;
uniform sampler2D u_state0;
uniform sampler2D u_state1;
uniform sampler2D u_state2;
uniform sampler2D u_light_measure; // texel l: (directional, positional) measures
uniform int u_frame;
uniform int u_frame_height;

layout(location = 0) out vec4 o_axis1;
layout(location = 1) out vec4 o_axis2;
layout(location = 2) out vec4 o_state0;
layout(location = 3) out vec4 o_state1;
layout(location = 4) out vec4 o_state2;

void write_state(vec3 dp[2], vec3 dd[2], float diffuse) {
    o_state0 = vec4(dp[0], dd[0].x);
    o_state1 = vec4(dp[1], dd[0].y);
    o_state2 = vec4(dd[1], dd[0].z);
    o_axis2.w = diffuse;
}

// The light a photon left from: the point light at p, the area light whose
// primitive it left, or the triangle light holding that primitive.
int emitting_light(vec3 p, int prim) {
    for (int l = 0; l < u_light_count; ++l) {
        int kind = light_kind(l);
        if (light_kind_is(kind, LIGHT_POINT)) {
            if (prim < 0 && all(equal(light_texel(l, 1).xyz, p))) return l;
        } else if (light_kind_is(kind, LIGHT_AREA)) {
            if (prim >= 0 && int(light_texel(l, 5).z) == prim) return l;
        } else {
            vec4 range = light_texel(l, 1);
            for (int i = 0; i < int(range.y); ++i) {
                if (int(light_triangle_texel(int(range.x) + i).y) == prim) return l;
            }
        }
    }
    return 0;
}

// The normal's differential along dp on a curved primitive (0 on flat ones);
// `side` is +1 or -1 as the normal used is the outward one or its opposite.
vec3 normal_differential(int prim, vec3 dp, float side) {
    int kind = int(primitive_texel(prim, 0).x);
    vec4 a = primitive_texel(prim, 1);
    if (kind == PRIM_SPHERE) return side * dp / a.w;
    if (kind == PRIM_CYLINDER) {
        vec3 axis = primitive_texel(prim, 2).xyz;
        return side * (dp - dot(dp, axis) * axis) / a.w;
    }
    return vec3(0.0);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    o_axis1 = vec4(0.0);
    o_axis2 = vec4(0.0);
    vec3 zero[2] = vec3[2](vec3(0.0), vec3(0.0));
    write_state(zero, zero, 0.0);
    vec4 position = texelFetch(u_position, px, 0);
    vec4 incoming = texelFetch(u_incoming, px, 0);
    vec4 outgoing = texelFetch(u_outgoing, px, 0);
    vec3 dp[2], dd[2];
    if (u_frame == 0) {
        if (incoming.w == 0.0) return; // not emitted
        vec3 d = outgoing.xyz;
        vec3 t[2];
        basis_around(d, t[0], t[1]);
        int l = emitting_light(position.xyz, int(outgoing.w));
        vec2 measure = texelFetch(u_light_measure, ivec2(l, 0), 0).xy;
        float s = sqrt(measure.x), v = sqrt(measure.y);
        for (int k = 0; k < 2; ++k) {
            dp[k] = v * t[k];
            dd[k] = s * t[k];
        }
        write_state(dp, dd, 0.0);
        return;
    }
    if (position.w < 0.0) return; // no hit this frame
    ivec2 prev = px - ivec2(0, u_frame_height);
    vec4 s0 = texelFetch(u_state0, prev, 0);
    vec4 s1 = texelFetch(u_state1, prev, 0);
    vec4 s2 = texelFetch(u_state2, prev, 0);
    float diffuse = texelFetch(u_axis2, prev, 0).w;
    vec3 origin = texelFetch(u_position, prev, 0).xyz;
    dp = vec3[2](s0.xyz, s1.xyz);
    dd = vec3[2](vec3(s0.w, s1.w, s2.w), s2.xyz);
    vec3 d = incoming.xyz;
    vec3 p = position.xyz;
    int prim = int(outgoing.w);
    vec3 n = geometric_normal(prim, p);
    float side = dot(n, d) < 0.0 ? 1.0 : -1.0;
    vec3 nf = side * n;
    // Transfer (Igehy): dp' = dp + t dd + dt d, with dt keeping dp' on the surface.
    float t = dot(p - origin, d);
    for (int k = 0; k < 2; ++k) {
        vec3 moved = dp[k] + t * dd[k];
        dp[k] = moved - dot(moved, nf) / dot(d, nf) * d;
    }
    o_axis1 = vec4(dp[0], diffuse);
    o_axis2 = vec4(dp[1], 0.0);
    if (incoming.w == 0.0) {
        write_state(zero, zero, diffuse);
        return; // absorbed here: nothing leaves
    }
    int mat = int(position.w);
    Bsdf b = material_bsdf(mat);
    vec3 next = outgoing.xyz;
    if (bsdf_is_diffuse(b)) {
        // Re-emission from a virtual origin v behind p (equation 13), the
        // old footprint first widened by the roulette (area / q).
        vec3 albedo = b.color;
        float q = max(albedo.r, max(albedo.g, albedo.b));
        float v = sqrt(length(cross(dp[0], dp[1])) / q);
        vec3 t2[2];
        basis_around(next, t2[0], t2[1]);
        for (int k = 0; k < 2; ++k) {
            dp[k] = v * t2[k];
            dd[k] = t2[k];
        }
        write_state(dp, dd, 1.0);
        return;
    }
    // Mirror or glass: the normal the tracer used (the shading normal if the
    // direction it gives is the one taken), reflected or refracted.
    vec3 m = nf;
    bool entering = dot(n, d) < 0.0;
    float ior = b.kind == MAT_GLASS ? b.ior : 0.0; // mirrors and metals reflect
    bool reflected = dot(next, nf) > 0.0;
    if (has_shading_normal(prim)) {
        vec3 ms = shading_normal(prim, p, n) * side;
        bool used;
        vec3 again = specular_shaded(d, nf, ms, ior, entering, reflected ? 0.0 : 0.99999994, used);
        if (used && dot(again, next) > 0.9999) m = ms;
    }
    vec3 dn[2];
    for (int k = 0; k < 2; ++k) dn[k] = normal_differential(prim, dp[k], side);
    float dm = dot(d, m);
    float q = 1.0;
    if (reflected || ior == 0.0) {
        for (int k = 0; k < 2; ++k) {
            float ddm = dot(dd[k], m) + dot(d, dn[k]);
            dd[k] = dd[k] - 2.0 * (dm * dn[k] + ddm * m);
        }
        if (ior != 0.0) {
            float cos_t;
            q = fresnel_dielectric(-dm, entering ? 1.0 / ior : ior, cos_t);
        }
    } else {
        float eta = entering ? 1.0 / ior : ior;
        float cos_t;
        q = 1.0 - fresnel_dielectric(-dm, eta, cos_t);
        float mu = -eta * dm - cos_t;
        for (int k = 0; k < 2; ++k) {
            float ddm = dot(dd[k], m) + dot(d, dn[k]);
            float dmu = (-eta - eta * eta * dm / cos_t) * ddm;
            dd[k] = eta * dd[k] + mu * dn[k] + dmu * m;
        }
    }
    float widen = q > 0.0 ? inversesqrt(q) : 1.0;
    for (int k = 0; k < 2; ++k) {
        dp[k] *= widen;
        dd[k] *= widen;
    }
    write_state(dp, dd, diffuse);
}
