#version 450 core
// Adaptive sampling, one level: each pixel's plan (render/adaptive_plan.glsl)
// and the interpolated light of those it interpolates. Reads the known light
// of coarser levels only.
#include "render/adaptive_plan.glsl"

layout(location = 0) out vec4 o_plan; // rgb interpolated, w = plan

void main() {
    vec3 interpolated;
    int plan = adaptive_plan(ivec2(gl_FragCoord.xy), interpolated);
    o_plan = vec4(interpolated, float(plan));
}
