// Mirror and glass directions, about a surface's shading normal where it has
// one. src/reference/shading.rs holds the same functions in Rust.
#include "common/fresnel.glsl"

// The direction d leaves by at a mirror (ior = 0) or glass (ior > 0) about
// the unit normal m facing d (dot(d, m) < 0). Glass reflects when u < F
// (exact unpolarised Fresnel) and refracts otherwise; `entering` says whether
// d enters the glass, which the geometric normal decides.
vec3 specular_about(vec3 d, vec3 m, float ior, bool entering, float u) {
    if (ior == 0.0) return reflect(d, m);
    float eta = entering ? 1.0 / ior : ior;
    float cos_i = -dot(d, m);
    float cos_t;
    float f = fresnel_dielectric(cos_i, eta, cos_t);
    return u < f ? reflect(d, m) : eta * d + (eta * cos_i - cos_t) * m;
}

// What a path that carries radiance (an eye path, a gather ray) multiplies
// its throughput by as it leaves d for next at the surface whose geometric
// normal nf faces d: (eta_i / eta_t)^2 where it refracts, 1 otherwise.
// Radiance crossing from index eta_t into eta_i scales so (Veach's thesis,
// 5.2: the solid angle is compressed on the denser side); a path that enters
// glass and leaves it again takes eta and 1 / eta, so through a closed ball
// the two cancel. Photons and VPLs carry flux, which refraction does not
// scale: light paths never call this.
float radiance_refraction_scale(vec3 next, vec3 nf, float ior, bool entering) {
    if (ior == 0.0 || dot(next, nf) >= 0.0) return 1.0;
    float eta = entering ? 1.0 / ior : ior;
    return eta * eta;
}

// The same about the shading normal ms (on the side of the geometric normal
// nf, both facing d), unless d arrives from behind ms, or the new direction
// leaves on the wrong side of the geometric surface (a reflection below it,
// a refraction above it): then about nf. `used`: whether ms was used.
vec3 specular_shaded(vec3 d, vec3 nf, vec3 ms, float ior, bool entering, float u, out bool used) {
    used = false;
    if (dot(d, ms) < 0.0) {
        vec3 next = specular_about(d, ms, ior, entering, u);
        bool reflected = dot(next, ms) > 0.0;
        if (reflected == (dot(next, nf) > 0.0)) {
            used = true;
            return next;
        }
    }
    return specular_about(d, nf, ior, entering, u);
}
