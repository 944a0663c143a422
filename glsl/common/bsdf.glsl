// The BSDF layer: every surface's scattering as one value, `Bsdf`, with
// evaluate, sample and pdf. Eye paths, photon bounces, final gather, SPPM and
// VCM ask it what a surface does; where they go on or stop is theirs
// (a diffuse lobe takes visible points and stores photons, a delta lobe
// continues the path, a glossy lobe is sampled and evaluated).
// src/twins/bsdf.rs holds the same functions in Rust.
//
// Conventions (pbrt's): wo and wi point away from the surface; f(wo, wi) is
// without the cosine; pdfs are per unit solid angle; a sample's weight is
// f |cos wi| / pdf, or for a delta lobe the factor the path takes.
// Lobes are BSDF_DIFFUSE, BSDF_DELTA and BSDF_GLOSSY (src/layout.rs).
#include "common/scene.glsl"
#include "common/sampling.glsl"
#include "common/specular.glsl"

struct Bsdf {
    int kind;    // MAT_*
    vec3 color;  // diffuse albedo, mirror reflectance, a conductor's tint
    float ior;   // glass: the interior's index over the exterior's
    vec2 alpha;  // conductor: microfacet alpha along the frame's t and b; 0: smooth
    vec3 eta;    // conductor: complex index eta + i k, per channel
    vec3 k;
    int model;   // a rough lobe's microfacet model: MICROFACET_* bits
};

// Material mat's BSDF (src/scene/pack.rs lays out its texels). A conductor's
// index is read only where the scene holds one.
Bsdf material_bsdf(int mat) {
    vec4 head = material_texel(mat, 0);
    vec4 color = material_texel(mat, 1);
    Bsdf b = Bsdf(int(head.x), color.rgb, head.y, head.zw, vec3(1.0), vec3(0.0), int(color.w));
    if (SCENE_HAS_MATERIAL(MAT_CONDUCTOR) && b.kind == MAT_CONDUCTOR) {
        b.eta = material_texel(mat, 2).rgb;
        b.k = material_texel(mat, 3).rgb;
    }
    return b;
}

// A shading frame: n the unit normal on the side wo leaves from, t and b
// tangents (a rough lobe's alpha.x lies along t).
struct Frame {
    vec3 t;
    vec3 b;
    vec3 n;
};

Frame frame_around(vec3 n) {
    Frame f;
    basis_around(n, f.t, f.b);
    f.n = n;
    return f;
}

vec3 to_local(Frame f, vec3 v) { return vec3(dot(v, f.t), dot(v, f.b), dot(v, f.n)); }
vec3 from_local(Frame f, vec3 v) { return v.x * f.t + v.y * f.b + v.z * f.n; }

int bsdf_lobes(Bsdf b) {
    if (b.kind == MAT_DIFFUSE) return BSDF_DIFFUSE;
    // (Folded away where the scene holds no metal.)
    if (SCENE_HAS_MATERIAL(MAT_CONDUCTOR) && b.kind == MAT_CONDUCTOR && b.alpha.x * b.alpha.y > 0.0)
        return BSDF_GLOSSY;
    if (b.kind == MAT_EMITTER) return 0;
    return BSDF_DELTA;
}

bool bsdf_is_diffuse(Bsdf b) { return bsdf_lobes(b) == BSDF_DIFFUSE; }
bool bsdf_is_delta(Bsdf b) { return bsdf_lobes(b) == BSDF_DELTA; }

// A diffuse lobe's constant f, which a method may take out of a sum over
// light samples.
vec3 bsdf_lambert(Bsdf b) { return b.color / PI; }

// Unpolarised Fresnel reflectance of a conductor of index eta + i k at the
// cosine c to the normal (exact; Lagarde's form of the complex equations).
vec3 fresnel_conductor(float c, vec3 eta, vec3 k) {
    float cos2 = c * c;
    float sin2 = 1.0 - cos2;
    vec3 eta2 = eta * eta;
    vec3 k2 = k * k;
    vec3 t0 = eta2 - k2 - vec3(sin2);
    vec3 a2b2 = sqrt(t0 * t0 + 4.0 * eta2 * k2);
    vec3 t1 = a2b2 + vec3(cos2);
    vec3 a = sqrt(max(0.5 * (a2b2 + t0), vec3(0.0)));
    vec3 t2 = 2.0 * c * a;
    vec3 rs = (t1 - t2) / (t1 + t2);
    vec3 t3 = cos2 * a2b2 + vec3(sin2 * sin2);
    vec3 t4 = t2 * sin2;
    vec3 rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5 * (rp + rs);
}

// Trowbridge-Reitz (GGX) in the local frame (z the normal), as pbrt-v4's
// TrowbridgeReitzDistribution: D, Smith's Lambda, G1.
float ggx_d(vec2 alpha, vec3 m) {
    if (m.z <= 0.0) return 0.0;
    float e = (m.x * m.x) / (alpha.x * alpha.x) + (m.y * m.y) / (alpha.y * alpha.y) + m.z * m.z;
    return 1.0 / (PI * alpha.x * alpha.y * e * e);
}

float ggx_lambda(vec2 alpha, vec3 w) {
    float z2 = w.z * w.z;
    if (z2 == 0.0) return 1e30;
    float a2t2 = (w.x * w.x * alpha.x * alpha.x + w.y * w.y * alpha.y * alpha.y) / z2;
    return 0.5 * (sqrt(1.0 + a2t2) - 1.0);
}

float ggx_g1(vec2 alpha, vec3 w) { return 1.0 / (1.0 + ggx_lambda(alpha, w)); }

// The distribution of normals visible from wo (Heitz 2018), sampled from u.
vec3 ggx_sample_visible(vec2 alpha, vec3 wo, vec2 u) {
    vec3 wh = normalize(vec3(alpha.x * wo.x, alpha.y * wo.y, wo.z));
    if (wh.z < 0.0) wh = -wh;
    vec3 t1 = wh.z < 0.99999 ? normalize(cross(vec3(0.0, 0.0, 1.0), wh)) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(wh, t1);
    float r = sqrt(u.x);
    float phi = 2.0 * PI * u.y;
    vec2 p = vec2(r * cos(phi), r * sin(phi));
    float h = sqrt(max(0.0, 1.0 - p.x * p.x));
    p.y = mix(h, p.y, 0.5 * (1.0 + wh.z));
    float pz = sqrt(max(0.0, 1.0 - dot(p, p)));
    vec3 nh = p.x * t1 + p.y * t2 + pz * wh;
    return normalize(vec3(alpha.x * nh.x, alpha.y * nh.y, max(1e-6, nh.z)));
}

// The density of visible normal m seen from wo.
float ggx_pdf_visible(vec2 alpha, vec3 wo, vec3 m) {
    return ggx_g1(alpha, wo) / abs(wo.z) * ggx_d(alpha, m) * abs(dot(wo, m));
}

// Beckmann's distribution (Mitsuba's default for a rough conductor), with
// Walter et al.'s rational approximation of its Smith G1, as Mitsuba uses
// it, and sampled as D(m) cos(m) (Walter et al. 2007).
float beckmann_d(vec2 alpha, vec3 m) {
    if (m.z <= 0.0) return 0.0;
    float z2 = m.z * m.z;
    float e = ((m.x * m.x) / (alpha.x * alpha.x) + (m.y * m.y) / (alpha.y * alpha.y)) / z2;
    return exp(-e) / (PI * alpha.x * alpha.y * z2 * z2);
}

float beckmann_lambda(vec2 alpha, vec3 w) {
    float r = sqrt(w.x * w.x * alpha.x * alpha.x + w.y * w.y * alpha.y * alpha.y);
    if (r == 0.0) return 0.0;
    float a = abs(w.z) / r;
    if (a >= 1.6) return 0.0;
    if (a == 0.0) return 1e30;
    float g1 = (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
    return 1.0 / g1 - 1.0;
}

vec3 beckmann_sample(vec2 alpha, vec2 u) {
    float phi = 2.0 * PI * u.y;
    // The azimuth of an anisotropic lobe, stretched (and kept in phi's quadrant).
    if (alpha.x != alpha.y) phi = atan(alpha.y * sin(phi), alpha.x * cos(phi));
    float c = cos(phi), s = sin(phi);
    float tan2 = -log(max(1.0 - u.x, 1e-30)) / (c * c / (alpha.x * alpha.x) + s * s / (alpha.y * alpha.y));
    float cos_t = 1.0 / sqrt(1.0 + tan2);
    float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
    return vec3(sin_t * c, sin_t * s, cos_t);
}

// The lobe's microfacet model: its distribution, its Smith Lambda, and the
// masking-shadowing term, height-correlated (pbrt) or the product of the
// two directions' G1 (Mitsuba).
bool is_beckmann(Bsdf b) { return (b.model & MICROFACET_BECKMANN) != 0; }
float mf_d(Bsdf b, vec3 m) { return is_beckmann(b) ? beckmann_d(b.alpha, m) : ggx_d(b.alpha, m); }
float mf_lambda(Bsdf b, vec3 w) {
    return is_beckmann(b) ? beckmann_lambda(b.alpha, w) : ggx_lambda(b.alpha, w);
}
float mf_g(Bsdf b, vec3 wo, vec3 wi) {
    float lo = mf_lambda(b, wo), li = mf_lambda(b, wi);
    if ((b.model & MICROFACET_SEPARABLE) != 0) return 1.0 / ((1.0 + lo) * (1.0 + li));
    return 1.0 / (1.0 + lo + li);
}

// The density of the sampled normal m seen from wo: the visible normals for
// GGX, D(m) cos(m) for Beckmann.
float mf_pdf_m(Bsdf b, vec3 wo, vec3 m) {
    if (is_beckmann(b)) return beckmann_d(b.alpha, m) * m.z;
    return ggx_pdf_visible(b.alpha, wo, m);
}

// f(wo, wi) of the non-delta lobes, local directions.
vec3 bsdf_eval_local(Bsdf b, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
    if (b.kind == MAT_DIFFUSE) return bsdf_lambert(b);
    if (bsdf_lobes(b) != BSDF_GLOSSY) return vec3(0.0);
    vec3 m = wo + wi;
    if (dot(m, m) == 0.0) return vec3(0.0);
    m = normalize(m);
    vec3 f = fresnel_conductor(abs(dot(wo, m)), b.eta, b.k);
    return b.color * f * (mf_d(b, m) * mf_g(b, wo, wi) / (4.0 * wo.z * wi.z));
}

float bsdf_pdf_local(Bsdf b, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
    if (b.kind == MAT_DIFFUSE) return wi.z / PI;
    if (bsdf_lobes(b) != BSDF_GLOSSY) return 0.0;
    vec3 m = wo + wi;
    if (dot(m, m) == 0.0) return 0.0;
    m = normalize(m);
    return mf_pdf_m(b, wo, m) / (4.0 * abs(dot(wo, m)));
}

vec3 bsdf_eval(Bsdf b, Frame f, vec3 wo, vec3 wi) {
    return bsdf_eval_local(b, to_local(f, wo), to_local(f, wi));
}

float bsdf_pdf(Bsdf b, Frame f, vec3 wo, vec3 wi) {
    return bsdf_pdf_local(b, to_local(f, wo), to_local(f, wi));
}

struct BsdfSample {
    vec3 wi;     // unit
    vec3 weight; // f |cos wi| / pdf (a delta lobe: the factor the path takes)
    float pdf;   // per solid angle; 0 for a delta lobe
    int lobe;    // BSDF_*; 0: no sample
};

// A sample of a diffuse or glossy lobe from u in [0, 1)^2. The diffuse lobe
// is cosine-distributed about f.n (common/sampling.glsl's sample_cosine).
BsdfSample bsdf_sample(Bsdf b, Frame f, vec3 wo, vec2 u) {
    BsdfSample s = BsdfSample(vec3(0.0), vec3(0.0), 0.0, 0);
    if (b.kind == MAT_DIFFUSE) {
        s.wi = sample_cosine(f.n, u.x, u.y);
        s.pdf = max(dot(s.wi, f.n), 0.0) / PI;
        s.weight = b.color;
        s.lobe = BSDF_DIFFUSE;
        return s;
    }
    if (bsdf_lobes(b) != BSDF_GLOSSY) return s;
    vec3 lo = to_local(f, wo);
    if (lo.z <= 0.0) return s;
    vec3 m = is_beckmann(b) ? beckmann_sample(b.alpha, u) : ggx_sample_visible(b.alpha, lo, u);
    if (dot(lo, m) <= 0.0) return s;
    vec3 li = reflect(-lo, m);
    if (li.z <= 0.0) return s;
    s.pdf = mf_pdf_m(b, lo, m) / (4.0 * abs(dot(lo, m)));
    if (!(s.pdf > 0.0)) return s;
    s.wi = normalize(from_local(f, li));
    s.weight = bsdf_eval_local(b, lo, li) * li.z / s.pdf;
    s.lobe = BSDF_GLOSSY;
    return s;
}

// A delta lobe's direction for a ray along d (= -wo) that meets the surface
// whose geometric normal nf faces d, with the shading normal ms (on nf's
// side; nf itself without vertex normals, `shaded` false) and u in [0, 1)
// choosing glass's reflection (u < F) or refraction. `entering`: whether d
// enters the glass, which the geometric normal decides. Returns the
// direction as common/specular.glsl gives it (unit up to rounding; callers
// normalise it); `used`: whether ms was used. `factor`: what the path takes:
// a mirror's reflectance, a smooth conductor's Fresnel times its tint, 1 at
// glass (the choice by F cancels F); radiance's (eta_i / eta_t)^2 where a
// path carrying radiance (`radiance`) refracts, which flux does not take.
vec3 bsdf_delta_direction(Bsdf b, vec3 d, vec3 nf, vec3 ms, bool shaded, bool entering, float u,
                          bool radiance, out vec3 factor, out bool used) {
    float ior = b.kind == MAT_GLASS ? b.ior : 0.0;
    vec3 next;
    used = false;
    if (shaded) next = specular_shaded(d, nf, ms, ior, entering, u, used);
    else next = specular_about(d, nf, ior, entering, u);
    factor = vec3(1.0);
    if (b.kind == MAT_MIRROR) factor = b.color;
    if (b.kind == MAT_CONDUCTOR) {
        vec3 m = used ? ms : nf;
        factor = b.color * fresnel_conductor(min(1.0, -dot(d, m)), b.eta, b.k);
    }
    if (radiance) factor *= radiance_refraction_scale(next, nf, ior, entering);
    return next;
}
