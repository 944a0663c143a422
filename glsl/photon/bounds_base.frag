#version 450 core
// Level 0 of the bounds reduction: each stored photon in use gives its
// position as both minimum and maximum; every other record gives an empty box.
uniform sampler2D u_position;
uniform sampler2D u_power;
uniform int u_record_width;
uniform int u_frame_height;
uniform int u_photons_used;
layout(location = 0) out vec4 o_min;
layout(location = 1) out vec4 o_max;
void main() {
    ivec2 t = ivec2(gl_FragCoord.xy);
    int photon = (t.y % u_frame_height) * u_record_width + t.x;
    o_min = vec4(3.0e38);
    o_max = vec4(-3.0e38);
    if (photon >= u_photons_used || texelFetch(u_power, t, 0).w == 0.0) return;
    vec3 p = texelFetch(u_position, t, 0).xyz;
    o_min = vec4(p, 0.0);
    o_max = vec4(p, 0.0);
}
