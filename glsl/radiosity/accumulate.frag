#version 450 core
// A shot's energy (shoot.frag's, at the tiles it ended on) added (blending)
// into radiosity and residual, and into the direct part when the shooters
// were lights. Retired tiles (no area) take nothing.
uniform sampler2D u_shot;
uniform sampler2D u_element_position; // w = area
uniform int u_lights;

layout(location = 0) out vec4 o_radiosity;
layout(location = 1) out vec4 o_residual;
layout(location = 2) out vec4 o_direct;
layout(location = 3) out vec4 o_deposited;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec4 db = texelFetch(u_element_position, px, 0).w > 0.0 ? texelFetch(u_shot, px, 0)
                                                             : vec4(0.0);
    o_radiosity = db;
    o_residual = db;
    o_direct = u_lights != 0 ? db : vec4(0.0);
    o_deposited = vec4(0.0);
}
