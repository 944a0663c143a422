#version 450 core
// Final gather (section 4.5; Jensen's two maps): the gather rays of one batch.
// The target is width x (height * batch): texel (x, y + j * height) holds gather
// ray j of pixel (x, y). Each ray leaves the pixel's first diffuse hit
// cosine-distributed about its viewer-facing normal, follows mirrors and glass
// as eye paths do (glass chooses by Fresnel, so no weight), and ends at the
// first diffuse hit, which becomes a query of the global photon map; where it
// refracts it takes radiance's (eta_i / eta_t)^2, as eye paths do. A ray that
// leaves the scene or meets an emitter gathers nothing: direct light is the
// shadow rays', and light reaching the pixel by specular paths alone is the
// caustic map's. Rays are cosine-distributed about the geometric normal, as
// the estimate's albedo / pi at the first hit assumes: on a mesh with vertex
// normals the gathered light follows the photon estimate's convention, not
// the shadow rays' shading-normal cosine. src/twins/final_gather.rs is the twin.
// With u_fade_distance = m > 0 the rays are IGI's bias compensation: a ray
// queries only where it meets a diffuse surface straight from the pixel's
// hit, weighted by 1 - f(d), the share of that connection IGI's bounded
// geometry term leaves out; paths through mirrors and glass are the caustic
// map's.
#include "common/scene.glsl"
#include "common/random.glsl"
#include "common/sampling.glsl"
#include "common/specular.glsl"
#include "common/addressing.glsl"
#include "common/vpl_bound.glsl"
#include "common/bsdf.glsl"

uniform sampler2D u_diffuse_position;   // the pixel's first diffuse hit, w = 1 where one exists
uniform sampler2D u_diffuse_normal;     // facing the viewer, w = material + 1
uniform isampler2D u_pixel;             // packed first hits: each texel's pixel index
uniform int u_packed;                   // 1: the first hits are packed (adaptive sampling)
uniform uint u_seed;
uniform int u_first_ray;                // index of this batch's ray 0 among the pixel's rays
uniform int u_batch_rays;               // rays in this batch: slots past them hold no query
uniform int u_image_height;
uniform int u_max_depth;                // specular bounces a gather ray may take
uniform float u_fade_distance;          // IGI's bound m: gather only what it leaves out (0: off)

layout(location = 0) out vec4 o_position;   // the gather hit, w = 1 where it is a query
layout(location = 1) out vec4 o_normal;     // facing the gather ray, w = material + 1
layout(location = 2) out vec4 o_throughput; // of the specular chain (1 without one), w = the primitive hit

void main() {
    ivec2 texel = ivec2(gl_FragCoord.xy);
    int j = texel.y / u_image_height;
    ivec2 px = ivec2(texel.x, texel.y - j * u_image_height);
    o_position = vec4(0.0);
    o_normal = vec4(0.0);
    o_throughput = vec4(0.0);
    vec4 first = texelFetch(u_diffuse_position, px, 0);
    if (first.w <= 0.0 || j >= u_batch_rays) return;
    vec3 n1 = texelFetch(u_diffuse_normal, px, 0).xyz;
    // A packed hit draws its own pixel's random numbers.
    ivec2 own = px;
    if (u_packed != 0)
        own = texel_of_index(texelFetch(u_pixel, px, 0).x, textureSize(u_diffuse_position, 0).x);
    uint rng = rng_init(u_seed, uvec2(own), GATHER_STREAM | uint(u_first_ray + j));
    float u1 = rng_next(rng), u2 = rng_next(rng);
    vec3 d = sample_cosine(n1, u1, u2);
    vec3 o = offset_origin(first.xyz, n1, d);
    vec3 throughput = vec3(1.0);
    for (int depth = 0; depth <= u_max_depth; ++depth) {
        vec4 hit;
        int prim = closest_hit(o, d, hit);
        if (prim < 0) return;
        int mat = primitive_material(prim);
        Bsdf b = material_bsdf(mat);
        if (b.kind == MAT_EMITTER) return;
        vec3 n;
        vec3 p = surface_point(prim, o, d, hit, n);
        bool entering = dot(n, d) < 0.0;
        vec3 nf = entering ? n : -n;
        if (u_fade_distance > 0.0) {
            if (!bsdf_is_diffuse(b)) return;
            float left_out = 1.0 - vpl_bound(length(p - first.xyz), u_fade_distance);
            if (left_out <= 0.0) return;
            throughput = vec3(left_out);
        }
        if (bsdf_is_diffuse(b)) {
            o_position = vec4(p, 1.0);
            o_normal = vec4(nf, float(mat + 1));
            o_throughput = vec4(throughput, float(prim));
            return;
        }
        bool shaded = has_shading_normal(prim);
        vec3 ms = nf;
        if (shaded) ms = shading_normal(prim, p, n) * (entering ? 1.0 : -1.0);
        if (SCENE_HAS_GLOSSY && bsdf_lobes(b) == BSDF_GLOSSY) {
            // A rough metal: on along a sample of its lobe; light that meets
            // it straight from an emitter is the caustic map's, as through a
            // mirror.
            float v1 = rng_next(rng);
            BsdfSample s = bsdf_sample(b, frame_around(ms), -d, vec2(v1, rng_next(rng)));
            if (s.lobe == 0 || dot(s.wi, nf) <= 0.0) return;
            throughput *= s.weight;
            d = s.wi;
            o = offset_origin(p, nf, d);
            continue;
        }
        if (!bsdf_is_delta(b)) return;
        float u = b.kind == MAT_GLASS ? rng_next(rng) : 0.0;
        // A gather ray carries radiance back to the pixel, as an eye path does.
        vec3 factor;
        bool used;
        vec3 next = bsdf_delta_direction(b, d, nf, ms, shaded, entering, u, true, factor, used);
        throughput *= factor;
        d = normalize(next);
        o = offset_origin(p, nf, d);
    }
}
