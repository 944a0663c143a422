#version 450 core
// One bounce of every photon (breadth-first): reads frame b-1 of the photon
// textures and writes frame b, a non-overlapping band of the same textures
// (a texture barrier between passes makes the previous frame visible).
// Diffuse hits store the photon, except its first hit (direct light is the
// shadow rays' job), and continue by Russian roulette (or end, when the scene
// stores caustics only: every photon alive at a diffuse hit then came by
// specular bounces alone); mirrors reflect; glass
// reflects or refracts by exact Fresnel. Lost or absorbed photons are marked
// dead, never compacted. On triangles with vertex normals, mirror and glass
// directions are taken about the shading normal, and the power takes the
// adjoint's shading-normal correction (below).
#include "common/scene.glsl"
#include "common/photon_random.glsl"
#include "common/sampling.glsl"
#include "common/specular.glsl"

uniform sampler2D u_position;
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform sampler2D u_outgoing;
uniform uint u_seed;
uniform int u_bounce;        // this frame, 1..
uniform int u_frame_height;
uniform int u_store_direct;  // 1: store first hits too (tests of the flux)
uniform int u_caustics_only; // 1: a diffuse hit ends the photon (stored if not its first)

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_power;
layout(location = 2) out vec4 o_incoming;
layout(location = 3) out vec4 o_outgoing;

// What the previous interaction multiplies the power by on the way out.
vec3 leaving_factor(int mat) {
    if (mat < 0) return vec3(1.0); // emission
    int kind = material_kind(mat);
    vec3 color = material_texel(mat, 1).rgb;
    if (kind == MAT_DIFFUSE) return color / max(color.r, max(color.g, color.b)); // roulette kept it
    if (kind == MAT_MIRROR) return color;
    return vec3(1.0);
}

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 prev = px - ivec2(0, u_frame_height);
    o_position = vec4(0.0, 0.0, 0.0, -1.0);
    o_power = vec4(0.0);
    o_incoming = vec4(0.0);
    o_outgoing = vec4(0.0, 0.0, 0.0, -1.0);
    vec4 last_incoming = texelFetch(u_incoming, prev, 0);
    if (last_incoming.w == 0.0) return; // dead since an earlier bounce
    vec4 last_position = texelFetch(u_position, prev, 0);
    vec4 last_outgoing = texelFetch(u_outgoing, prev, 0);
    vec3 power = texelFetch(u_power, prev, 0).rgb * leaving_factor(int(last_position.w));
    vec3 d = last_outgoing.xyz;
    int last_prim = int(last_outgoing.w);
    vec3 origin = last_position.xyz;
    if (last_prim >= 0) origin = offset_origin(origin, geometric_normal(last_prim, origin), d);

    vec4 hit;
    int prim = closest_hit(origin, d, hit);
    if (prim < 0) return; // left the scene
    int mat = primitive_material(prim);
    int kind = material_kind(mat);
    if (kind == MAT_EMITTER) return; // lights reflect nothing
    vec3 n;
    vec3 p = surface_point(prim, origin, d, hit, n);
    vec3 nf = dot(n, d) < 0.0 ? n : -n;
    ivec2 local = ivec2(px.x, px.y - u_bounce * u_frame_height);
    PhotonRandom rng = photon_random_init(u_seed, px, uvec2(local), 0x10000000u + uint(u_bounce));
    float u0 = photon_random_next(rng), u1 = photon_random_next(rng), u2 = photon_random_next(rng);
    bool stored = false;
    bool alive = true;
    vec3 next;
    // Vertex normals: the shading normal on the side the photon arrives at.
    bool shaded = has_shading_normal(prim);
    vec3 ms = nf;
    if (shaded) ms = shading_normal(prim, p, n) * (dot(n, d) < 0.0 ? 1.0 : -1.0);
    if (kind == MAT_DIFFUSE) {
        stored = u_bounce >= 2 || u_store_direct != 0;
        vec3 albedo = material_texel(mat, 1).rgb;
        alive = u_caustics_only == 0 && u0 < max(albedo.r, max(albedo.g, albedo.b));
        next = sample_cosine(nf, u1, u2);
        // The adjoint BSDF with a shading normal (Veach 1997, 5.3): the
        // photon's power, stored here and carried on (its direction is
        // cosine-distributed about the geometric normal), is weighted by
        // |w_in . n_s| / |w_in . n_g|, so that a density estimate with the
        // plain albedo / pi gives the radiance the eye side computes with the
        // shading normal's cosine.
        if (shaded) {
            float cos_g = -dot(nf, d);
            power *= cos_g > 0.0 ? max(-dot(ms, d), 0.0) / cos_g : 0.0;
        }
    } else {
        bool entering = dot(n, d) < 0.0;
        float ior = kind == MAT_MIRROR ? 0.0 : material_texel(mat, 0).y;
        if (shaded) {
            bool used;
            next = specular_shaded(d, nf, ms, ior, entering, u0, used);
            // The adjoint's correction for a specular bounce about n_s:
            // |w_in . n_s| |w_out . n_g| / (|w_in . n_g| |w_out . n_s|).
            float den = -dot(d, nf) * abs(dot(next, ms));
            if (used) power *= den > 0.0 ? (-dot(d, ms) * abs(dot(next, nf))) / den : 0.0;
        } else {
            next = specular_about(d, nf, ior, entering, u0);
        }
    }
    o_position = vec4(p, float(mat));
    o_power = vec4(power, stored ? 1.0 : 0.0);
    o_incoming = vec4(d, alive ? 1.0 : 0.0);
    o_outgoing = vec4(normalize(next), float(prim));
}
