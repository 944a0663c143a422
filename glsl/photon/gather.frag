#version 450 core
// Photon records in sorted order, power scaled to the emitted count in use:
// the photon map the radiance estimate reads (coherent cell by cell).
#include "common/addressing.glsl"

uniform isampler2D u_sorted;
uniform sampler2D u_position;
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform int u_sorted_width;
uniform int u_record_width;
uniform float u_power_scale;

layout(location = 0) out vec4 o_position; // xyz, w = 1 valid
layout(location = 1) out vec4 o_power;    // rgb
layout(location = 2) out vec4 o_incoming; // direction of arrival


void main() {
    ivec4 pair = texelFetch(u_sorted, ivec2(gl_FragCoord.xy), 0);
    o_position = vec4(0.0);
    o_power = vec4(0.0);
    o_incoming = vec4(0.0);
    if (pair.x == INVALID_KEY) return;
    ivec2 t = texel_of_index(pair.y, u_record_width);
    o_position = vec4(texelFetch(u_position, t, 0).xyz, 1.0);
    o_power = vec4(texelFetch(u_power, t, 0).rgb * u_power_scale, 0.0);
    o_incoming = vec4(texelFetch(u_incoming, t, 0).xyz, 0.0);
}
