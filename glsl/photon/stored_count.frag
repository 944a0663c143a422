#version 450 core
// Stored records of each photon, summed over its frames: one float per photon
// (the frame layout), read back to choose how many emitted photons to keep,
// a 16th of reading back the power texture of every frame.
uniform sampler2D u_power;
uniform int u_frame_height;
uniform int u_frames;
layout(location = 0) out vec4 o_count;
void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    float n = 0.0;
    for (int f = 0; f < u_frames; ++f) n += texelFetch(u_power, px + ivec2(0, f * u_frame_height), 0).w;
    o_count = vec4(n, 0.0, 0.0, 0.0);
}
