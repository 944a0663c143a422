#version 450 core
// Every bounce of one photon in one pass (the fused path; photon/trace.frag
// is the paper's pass per bounce): from its emission record in frame 0 it
// bounces until it ends, storing each frame's record through images at the
// texel the per-bounce pass would write, with the same random numbers.
// Frames after a photon's end are not written: the caller clears the power
// texture first, so their power (and stored flag) is 0, which is all a map
// build reads of them. o_last is the last frame in which the photon goes on
// (-1: not even emitted), whose maximum says how many frames the build reads.
#include "photon/bounce.glsl"

uniform sampler2D u_position;   // frame 0, as emission wrote it
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform sampler2D u_outgoing;
layout(rgba32f) uniform writeonly image2D u_position_out;
layout(rgba32f) uniform writeonly image2D u_power_out;
layout(rgba32f) uniform writeonly image2D u_incoming_out;
layout(rgba32f) uniform writeonly image2D u_outgoing_out;
uniform int u_frame_height;
uniform int u_frames;

layout(location = 0) out vec4 o_last;

void main() {
    ivec2 local = ivec2(gl_FragCoord.xy);
    PhotonRecord r = PhotonRecord(texelFetch(u_position, local, 0), texelFetch(u_power, local, 0),
                                  texelFetch(u_incoming, local, 0), texelFetch(u_outgoing, local, 0));
    int last = r.incoming.w != 0.0 ? 0 : -1;
    for (int b = 1; b < u_frames && r.incoming.w != 0.0; ++b) {
        ivec2 px = local + ivec2(0, b * u_frame_height);
        r = photon_bounce(r, px, local, b);
        imageStore(u_position_out, px, r.position);
        imageStore(u_power_out, px, r.power);
        imageStore(u_incoming_out, px, r.incoming);
        imageStore(u_outgoing_out, px, r.outgoing);
        if (r.incoming.w != 0.0) last = b;
    }
    o_last = vec4(float(last), 0.0, 0.0, 0.0);
}
