#version 450 core
// Zero over a tile's region: a shot tile's residual (nothing left to
// shoot), or a split tile's radiosity, residual and direct part.
layout(location = 0) out vec4 o_0;
layout(location = 1) out vec4 o_1;
layout(location = 2) out vec4 o_2;

void main() {
    o_0 = vec4(0.0);
    o_1 = vec4(0.0);
    o_2 = vec4(0.0);
}
