#version 450 core
// Progressive radiosity's visibility (Coombe and Harris, GPU Gems 2, 39.2.1),
// step 1: each vertex in the shooter's frame (t, b, n). item_buffer.geom
// clips and projects.
layout(location = 0) in vec3 a_position;
layout(location = 1) in float a_primitive;

uniform vec3 u_origin;
uniform vec3 u_tangent;
uniform vec3 u_bitangent;
uniform vec3 u_normal;

out vec3 g_local;
out vec3 g_world;
flat out int g_primitive;

void main() {
    vec3 m = a_position - u_origin;
    g_local = vec3(dot(m, u_tangent), dot(m, u_bitangent), dot(m, u_normal));
    g_world = a_position;
    g_primitive = int(a_primitive);
    gl_Position = vec4(0.0);
}
