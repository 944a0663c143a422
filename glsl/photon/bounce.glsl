// One bounce of one photon: from its record at frame bounce - 1 to its record
// at frame `bounce` (the paper's per-frame pass, photon/trace.frag, and the
// fused path, photon/trace_fused.frag, both call it, so both trace the same
// photons with the same random numbers).
// Diffuse hits store the photon, except its first hit (direct light is the
// shadow rays' job) and, when only specular-last photons are stored, a hit
// reached straight from another diffuse one; they continue by Russian
// roulette (or end, when the scene stores caustics only: every photon alive
// at a diffuse hit then came by specular bounces alone); delta lobes
// (common/bsdf.glsl) send it on: mirrors and metals reflect, glass reflects
// or refracts by exact Fresnel. On triangles with vertex normals,
// mirror and glass directions are taken about the shading normal, and the
// power takes the adjoint's shading-normal correction (below).
#include "common/scene.glsl"
#include "common/photon_random.glsl"
#include "common/sampling.glsl"
#include "common/bsdf.glsl"

uniform uint u_seed;
uniform int u_store_direct;  // 1: store first hits too (tests of the flux)
uniform int u_caustics_only; // 1: a diffuse hit ends the photon (stored if not its first)
uniform int u_specular_last_only; // 1: store only photons whose last bounce was specular

// A photon's record in one frame (photon/trace.frag names the channels).
struct PhotonRecord {
    vec4 position;
    vec4 power;
    vec4 incoming;
    vec4 outgoing;
};

// The record of a photon that is gone: not stored, not going on.
PhotonRecord dead_photon() {
    return PhotonRecord(vec4(0.0, 0.0, 0.0, -1.0), vec4(0.0), vec4(0.0), vec4(0.0, 0.0, 0.0, -1.0));
}

// What the previous interaction multiplies the power by on the way out: a
// diffuse lobe's albedo over the roulette's survival. (Delta and glossy
// lobes take their factor at the bounce.)
vec3 leaving_factor(int mat) {
    if (mat < 0) return vec3(1.0); // emission
    Bsdf b = material_bsdf(mat);
    vec3 color = b.color;
    if (bsdf_is_diffuse(b)) return color / max(color.r, max(color.g, color.b)); // roulette kept it
    return vec3(1.0);
}

// The record at frame `bounce` of the photon whose record at bounce - 1 is
// `last`; px is the new record's texel (its random stream), local its texel
// within the frame.
PhotonRecord photon_bounce(PhotonRecord last, ivec2 px, ivec2 local, int bounce) {
    PhotonRecord r = dead_photon();
    if (last.incoming.w == 0.0) return r; // dead since an earlier bounce
    vec3 power = last.power.rgb * leaving_factor(int(last.position.w));
    vec3 d = last.outgoing.xyz;
    int last_prim = int(last.outgoing.w);
    vec3 origin = last.position.xyz;
    if (last_prim >= 0) origin = offset_origin(origin, geometric_normal(last_prim, origin), d);

    vec4 hit;
    int prim = closest_hit(origin, d, hit);
    if (prim < 0) return r; // left the scene
    int mat = primitive_material(prim);
    Bsdf b = material_bsdf(mat);
    if (b.kind == MAT_EMITTER) return r; // lights reflect nothing
    vec3 n;
    vec3 p = surface_point(prim, origin, d, hit, n);
    vec3 nf = dot(n, d) < 0.0 ? n : -n;
    PhotonRandom rng = photon_random_init(u_seed, px, uvec2(local), 0x10000000u + uint(bounce));
    float u0 = photon_random_next(rng), u1 = photon_random_next(rng), u2 = photon_random_next(rng);
    bool stored = false;
    bool alive = true;
    vec3 next = d;
    // Vertex normals: the shading normal on the side the photon arrives at.
    bool shaded = has_shading_normal(prim);
    vec3 ms = nf;
    if (shaded) ms = shading_normal(prim, p, n) * (dot(n, d) < 0.0 ? 1.0 : -1.0);
    if (bsdf_is_diffuse(b)) {
        stored = bounce >= 2 || u_store_direct != 0;
        int last_mat = int(last.position.w);
        bool after_specular = last_mat >= 0 && !bsdf_is_diffuse(material_bsdf(last_mat));
        if (u_specular_last_only != 0) stored = stored && after_specular;
        vec3 albedo = b.color;
        alive = u_caustics_only == 0 && u0 < max(albedo.r, max(albedo.g, albedo.b));
        next = bsdf_sample(b, frame_around(nf), -d, vec2(u1, u2)).wi;
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
    } else if (SCENE_HAS_GLOSSY && bsdf_lobes(b) == BSDF_GLOSSY) {
        // A rough metal: not stored; on along a sample of the lobe about the
        // shading normal, the power times its weight (a reflection-only
        // microfacet BRDF is symmetric, so the adjoint is itself), with the
        // adjoint's shading-normal correction as at a specular bounce.
        BsdfSample s = bsdf_sample(b, frame_around(ms), -d, vec2(u1, u2));
        alive = s.lobe != 0 && dot(s.wi, nf) > 0.0;
        next = alive ? s.wi : d;
        power *= alive ? s.weight : vec3(0.0);
        if (shaded && alive) {
            float den = -dot(d, nf) * abs(dot(next, ms));
            power *= den > 0.0 ? (-dot(d, ms) * abs(dot(next, nf))) / den : 0.0;
        }
    } else if (SCENE_HAS_SPECULAR) { // else no lane is here: only diffuse surfaces reflect
        bool entering = dot(n, d) < 0.0;
        vec3 factor;
        bool used;
        next = bsdf_delta_direction(b, d, nf, ms, shaded, entering, u0, false, factor, used);
        // The adjoint's correction for a specular bounce about n_s:
        // |w_in . n_s| |w_out . n_g| / (|w_in . n_g| |w_out . n_s|).
        if (used) {
            float den = -dot(d, nf) * abs(dot(next, ms));
            power *= den > 0.0 ? (-dot(d, ms) * abs(dot(next, nf))) / den : 0.0;
        }
        power *= factor;
    }
    r.position = vec4(p, float(mat));
    r.power = vec4(power, stored ? 1.0 : 0.0);
    r.incoming = vec4(d, alive ? 1.0 : 0.0);
    r.outgoing = vec4(normalize(next), float(prim));
    return r;
}
