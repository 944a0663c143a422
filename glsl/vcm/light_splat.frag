#version 450 core
// A light tracing splat (vcm/light_splat.vert): its contribution, added.
flat in vec3 v_contribution;

layout(location = 0) out vec4 o_radiance;

void main() {
    o_radiance = vec4(v_contribution, 0.0);
}
