// The photons SPPM gathers at a visible point x (normal nf facing the eye)
// within squared radius r2: those of this iteration's map that arrive on the
// side the eye sees (the BRDF is zero for the other side) and pass the leak
// tests (VISIBILITY_TEST, DISC_TEST). Their power sums into `gathered` and
// their count (photon weights) into `m`. With START_BINS defined, every
// accepted photon is also counted into start_bins by its distance: bin j
// holds photons with d^2 in (r2 / 2^(j+1), r2 / 2^j], the last bin all
// nearer. render/sppm_update.frag and render/sppm_knn_start.frag share it.
#include "common/scene.glsl"
#include "common/photon_map.glsl"
#ifdef VISIBILITY_TEST
#include "common/visibility.glsl"
#endif

uniform sampler2D u_map_incoming;       // each photon's direction of arrival
#ifdef DISC_TEST
uniform float u_disc_radius;            // the disc's thickness is relative to this
#endif

#ifdef START_BINS
float start_bins[START_BINS];
#endif

void sppm_gather(vec3 x, vec3 nf, float r2, out vec3 gathered, out float m) {
    float r = sqrt(r2);
    vec3 cell_size = (u_grid_max - u_grid_min) / vec3(u_grid_resolution);
    ivec3 lo = clamp(ivec3(floor((x - r - u_grid_min) / cell_size)), ivec3(0), u_grid_resolution - 1);
    ivec3 hi = clamp(ivec3(floor((x + r - u_grid_min) / cell_size)), ivec3(0), u_grid_resolution - 1);
    gathered = vec3(0.0);
    m = 0.0;
#ifdef START_BINS
    for (int j = 0; j < START_BINS; ++j) start_bins[j] = 0.0;
#endif
    for (int cz = lo.z; cz <= hi.z; ++cz)
        for (int cy = lo.y; cy <= hi.y; ++cy)
            for (int cx = lo.x; cx <= hi.x; ++cx) {
                int cell = cx + u_grid_resolution.x * (cy + u_grid_resolution.y * cz);
                int base;
                int count = cell_photon_count(cell, base);
                if (count == 0) continue;
                // The next photon's texel from the last one's: no division a
                // photon (SIMD lanes pay dearly for them).
                ivec2 origin = photon_block_origin(base);
                ivec2 t = photon_texel(base, 0);
                for (int i = 0; i < count; ++i, t = photon_texel_next(t, origin)) {
                    vec3 photon = texelFetch(u_map_position, t, 0).xyz;
                    vec3 offset = photon - x;
                    float dist2 = dot(offset, offset);
                    if (dist2 >= r2) continue;
                    if (!photon_in_cell(photon, cell)) continue; // a hash bucket's other cells
                    if (dot(texelFetch(u_map_incoming, t, 0).xyz, nf) >= 0.0) continue;
#ifdef DISC_TEST
                    if (abs(dot(offset, nf)) > DISC_THICKNESS * u_disc_radius) continue;
#endif
#ifdef VISIBILITY_TEST
                    if (!photon_visible(x, nf, x + offset)) continue;
#endif
                    float w = photon_weight(cell, t);
                    gathered += texelFetch(u_map_power, t, 0).rgb;
                    m += w;
#ifdef START_BINS
                    // floor(log2(r2 / d^2)), clamped to the last bin.
                    int j = dist2 > 0.0 ? int(floor(log2(r2 / dist2))) : START_BINS - 1;
                    start_bins[clamp(j, 0, START_BINS - 1)] += w;
#endif
                }
            }
}
