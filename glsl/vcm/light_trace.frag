#version 450 core
// A light tracing splat (vcm/light_trace.vert): its contribution, added.
flat in vec3 v_contribution;

layout(location = 0) out vec4 o_radiance;

void main() {
    o_radiance = vec4(v_contribution, 0.0);
}
