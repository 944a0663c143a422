#version 450 core
// One iteration of stochastic progressive photon mapping (Hachisuka and Jensen
// 2009) at every pixel, in place (each fragment reads and writes only its own
// texels; a texture barrier separates iterations). This iteration's eye path
// ended at a visible point x (its first diffuse hit; none for background,
// emitters and lost paths). The pass gathers this iteration's photons within
// the pixel's radius R of x, counting only photons that arrive on the side of
// the surface the eye sees (the BRDF is zero for the other side), then
//   M > 0:  N' = N + alpha M,  R'^2 = R^2 (N + alpha M) / (N + M),
//           tau' = (tau + Phi) R'^2 / R^2,
// where Phi = throughput x albedo / pi x (power gathered): this iteration's
// BRDF and path weight, since x moves every iteration. Direct light (shadow
// rays at x, emitters along the path) is summed beside. The image is
// L = direct sum / i + tau / (pi R^2 i): photon power is already per emitted
// photon of one iteration's batch. The leak tests of the kNN estimate
// (VISIBILITY_TEST, DISC_TEST) may restrict the gather too; as R shrinks to
// zero they change nothing, so SPPM stays consistent with them.
#include "render/sppm_gather.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_state_flux;         // tau.rgb, R^2
uniform sampler2D u_state_direct;       // direct-light sum .rgb, N
uniform sampler2D u_direct;             // this iteration's direct light
uniform sampler2D u_diffuse_position;   // x, w = 1 where there is one
uniform sampler2D u_diffuse_normal;     // facing the eye, w = material + 1
uniform sampler2D u_diffuse_throughput; // path weight up to x
uniform float u_alpha;
// A pixel that has gathered nothing yet (N = 0) takes its first radius lazily:
// at most the grid's cell, so its gather stays within 2 cells per axis.
uniform float u_first_radius2;
uniform int u_gather;                   // 0: direct light only (the photon half off)

layout(location = 0) out vec4 o_flux;
layout(location = 1) out vec4 o_direct;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 flux = texelFetch(u_state_flux, px, 0);
    vec4 sums = texelFetch(u_state_direct, px, 0);
    sums.rgb += texelFetch(u_direct, px, 0).rgb;
    vec4 vp = texelFetch(u_diffuse_position, px, 0);
    vec4 nm = texelFetch(u_diffuse_normal, px, 0);
    int mat = int(nm.w) - 1;
    if (u_gather == 0 || vp.w <= 0.0 || mat < 0) {
        o_flux = flux;
        o_direct = sums;
        return;
    }
    float n_count = sums.w;
    float r2 = n_count > 0.0 ? flux.w : min(flux.w, u_first_radius2);
    vec3 gathered;
    float m;
    sppm_gather(vp.xyz, nm.xyz, r2, gathered, m);
    if (m > 0.0) {
        vec3 albedo = material_bsdf(mat).color; // a diffuse lobe's albedo
        vec3 phi = texelFetch(u_diffuse_throughput, px, 0).rgb * (albedo / PI) * gathered;
        float g = (n_count + u_alpha * m) / (n_count + m);
        flux.rgb = (flux.rgb + phi) * g;
        r2 *= g;
        n_count += u_alpha * m;
    }
    o_flux = vec4(flux.rgb, r2);
    o_direct = vec4(sums.rgb, n_count);
}
