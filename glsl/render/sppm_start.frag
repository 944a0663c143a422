#version 450 core
// Each pixel's first SPPM radius, at the first iteration, at its visible
// point x: the smallest of the maximum radius and these bounds:
// - u_pixels > 0: u_pixels pixel footprints at x: the width a pixel's cone
//   has at x's distance from the camera. The blur then starts at a few
//   pixels wherever x lies, whatever the scene's scale.
// - START_PHOTONS: the radius that holds the k nearest photons of that
//   iteration's map (progressive photon mapping's original choice, Hachisuka,
//   Ogaki and Jensen 2008), or the maximum where fewer than k lie within it.
//   The photons SPPM would gather within the maximum radius are counted by
//   distance, in bins a factor of 2 apart in d^2 (render/sppm_gather.glsl);
//   the radius is the outer edge of the bin where the count from the centre
//   reaches k: the k-th nearest distance, rounded up by at most sqrt(2).
//   (The paper's kNN-grid search would not do: it keeps the first k photons
//   met in cell order, which can lie a cell away.) Within the footprint
//   bound, bright caustics start smaller than their footprints.
// Pixels with no visible point, or that have gathered already, keep theirs.
#ifdef START_PHOTONS
#define START_BINS 16
#include "render/sppm_gather.glsl"
uniform int u_k;
#endif

uniform sampler2D u_state_flux;         // tau.rgb, R^2
uniform sampler2D u_state_direct;       // direct-light sum .rgb, N
uniform sampler2D u_diffuse_position;   // x, w = 1 where there is one
uniform sampler2D u_diffuse_normal;     // facing the eye, w = material + 1
uniform float u_first_radius2;          // the maximum radius, squared
uniform vec3 u_camera_position;
uniform float u_pixel_angle;            // a pixel's height over its distance
uniform float u_pixels;

layout(location = 0) out vec4 o_flux;
layout(location = 1) out vec4 o_direct;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 flux = texelFetch(u_state_flux, px, 0);
    vec4 sums = texelFetch(u_state_direct, px, 0);
    o_flux = flux;
    o_direct = sums;
    vec4 vp = texelFetch(u_diffuse_position, px, 0);
    vec4 nm = texelFetch(u_diffuse_normal, px, 0);
    if (sums.w > 0.0 || vp.w <= 0.0 || int(nm.w) < 1) return;
    float r2 = min(flux.w, u_first_radius2);
    if (u_pixels > 0.0) {
        float f = u_pixels * u_pixel_angle * distance(u_camera_position, vp.xyz);
        r2 = min(r2, f * f);
    }
    o_flux.w = r2;
#ifdef START_PHOTONS
    vec3 gathered;
    float m;
    sppm_gather(vp.xyz, nm.xyz, r2, gathered, m);
    float inside = 0.0;
    for (int j = START_BINS - 1; j >= 0; --j) {
        inside += start_bins[j];
        if (inside >= float(u_k)) {
            o_flux.w = r2 / exp2(float(j));
            return;
        }
    }
#endif
}
