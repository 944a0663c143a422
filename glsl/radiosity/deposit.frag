#version 450 core
// A caustic record's reflected power density, added (blending) into the
// element's radiosity, residual and direct part (deposit.vert), and into
// what was deposited, which a gather hit keeps when shadow rays replace the
// rest of its direct part (lookup.frag).
flat in vec3 v_radiosity;

layout(location = 0) out vec4 o_radiosity;
layout(location = 1) out vec4 o_residual;
layout(location = 2) out vec4 o_direct;
layout(location = 3) out vec4 o_deposited;

void main() {
    o_radiosity = vec4(v_radiosity, 0.0);
    o_residual = o_radiosity;
    o_direct = o_radiosity;
    o_deposited = o_radiosity;
}
