#version 450 core
// The floor of a pass over n records: read one RGBA32F texel, write it.
uniform sampler2D u_texels;
layout(location = 0) out vec4 o_texel;
void main() {
    o_texel = texelFetch(u_texels, ivec2(gl_FragCoord.xy), 0);
}
