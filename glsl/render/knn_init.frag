#version 450 core
// Starts the search: empty sums, ring 0; pixels with no diffuse hit (background,
// emitters, paths lost among specular surfaces) are done before they start.
uniform sampler2D u_query_position;
layout(location = 0) out vec4 o_flux;
layout(location = 1) out ivec4 o_cursor;
layout(location = 2) out ivec4 o_done;
void main() {
    bool has_query = texelFetch(u_query_position, ivec2(gl_FragCoord.xy), 0).w > 0.0;
    o_flux = vec4(0.0);
    o_cursor = ivec4(0);
    o_done = ivec4(has_query ? 0 : 1, 0, 0, 0);
}
