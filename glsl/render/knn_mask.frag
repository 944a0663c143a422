#version 450 core
// The computation mask: passes (and so sets the stencil) only where the search
// is done, so later passes reject those pixels before shading them.
uniform isampler2D u_state_done;
layout(location = 0) out vec4 o_unused;
void main() {
    if (texelFetch(u_state_done, ivec2(gl_FragCoord.xy), 0).x == 0) discard;
    o_unused = vec4(0.0);
}
