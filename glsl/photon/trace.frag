#version 450 core
// One bounce of every photon (breadth-first, the paper's way): reads frame
// b-1 of the photon textures and writes frame b, a non-overlapping band of the
// same textures (a texture barrier between passes makes the previous frame
// visible). Lost or absorbed photons are marked dead, never compacted.
// Channels: position xyz, w = material (-1: none); power rgb, w = 1 where
// stored; incoming direction, w = 1 if the photon goes on; outgoing
// direction, w = primitive hit (-1: none).
#include "photon/bounce.glsl"

uniform sampler2D u_position;
uniform sampler2D u_power;
uniform sampler2D u_incoming;
uniform sampler2D u_outgoing;
uniform int u_bounce;        // this frame, 1..
uniform int u_frame_height;

layout(location = 0) out vec4 o_position;
layout(location = 1) out vec4 o_power;
layout(location = 2) out vec4 o_incoming;
layout(location = 3) out vec4 o_outgoing;

void main() {
    ivec2 px = ivec2(gl_FragCoord.xy);
    ivec2 prev = px - ivec2(0, u_frame_height);
    PhotonRecord last = PhotonRecord(texelFetch(u_position, prev, 0), texelFetch(u_power, prev, 0),
                                     texelFetch(u_incoming, prev, 0), texelFetch(u_outgoing, prev, 0));
    ivec2 local = ivec2(px.x, px.y - u_bounce * u_frame_height);
    PhotonRecord r = photon_bounce(last, px, local, u_bounce);
    o_position = r.position;
    o_power = r.power;
    o_incoming = r.incoming;
    o_outgoing = r.outgoing;
}
