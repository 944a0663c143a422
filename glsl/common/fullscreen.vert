#version 450 core
// One triangle that covers the viewport, built from gl_VertexID: no vertex buffer.
void main() {
    vec2 p = vec2(float((gl_VertexID & 1) << 2), float((gl_VertexID & 2) << 1)) - 1.0;
    gl_Position = vec4(p, 0.0, 1.0);
}
