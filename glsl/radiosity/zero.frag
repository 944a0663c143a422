#version 450 core
// Zero over a tile's region: a shot tile's residual (nothing left to
// shoot), or a split tile's radiosity, residual, direct part and deposit.
layout(location = 0) out vec4 o_0;
layout(location = 1) out vec4 o_1;
layout(location = 2) out vec4 o_2;
layout(location = 3) out vec4 o_3;

void main() {
    o_0 = vec4(0.0);
    o_1 = vec4(0.0);
    o_2 = vec4(0.0);
    o_3 = vec4(0.0);
}
