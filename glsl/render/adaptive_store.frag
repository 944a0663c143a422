#version 450 core
// Adaptive sampling, one level: the known global light of this level's pixels,
// computed (the estimate's composed indirect light plus final gather's) or
// interpolated; other pixels keep theirs.
#include "render/adaptive_plan.glsl"
#include "common/addressing.glsl"

uniform sampler2D u_plan;          // rgb interpolated, w = plan (render/adaptive_plan.glsl)
uniform isampler2D u_slot;         // pixel -> its packed texel index (adaptive_compact.frag)
uniform sampler2D u_estimate;      // packed: composed estimate without direct light
uniform sampler2D u_gathered;      // packed: final gather's indirect light
uniform int u_has_estimate;
uniform int u_has_gather;
uniform int u_packed;              // 0: u_estimate is a full-resolution image (adaptive SPPM's pilot)

layout(location = 0) out vec4 o_value;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 plan = texelFetch(u_plan, p, 0);
    int kind = int(plan.w);
    if (kind == PLAN_NONE) discard;
    vec3 v = vec3(0.0);
    if (kind == PLAN_COMPUTE) {
        ivec2 s = u_packed != 0 ? texel_of_index(texelFetch(u_slot, p, 0).x, textureSize(u_plan, 0).x) : p;
        if (u_has_estimate != 0) v += texelFetch(u_estimate, s, 0).rgb;
        if (u_has_gather != 0) v += texelFetch(u_gathered, s, 0).rgb;
    } else if (kind == PLAN_INTERPOLATE) {
        v = plan.rgb;
    }
    o_value = vec4(v, 1.0);
}
