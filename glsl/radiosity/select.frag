#version 450 core
flat in int v_patch;

layout(location = 0) out vec4 o_patch;

void main() {
    o_patch = vec4(float(v_patch), 0.0, 0.0, 1.0);
}
