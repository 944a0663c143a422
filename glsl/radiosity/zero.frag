#version 450 core
// A shot patch's residual, drawn over its tile: nothing left to shoot.
layout(location = 0) out vec4 o_residual;

void main() {
    o_residual = vec4(0.0);
}
