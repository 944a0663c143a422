#version 450 core
// Step 2: the hemispherical projection. Each triangle is clipped in the
// shooter's frame to the half-space in front of it (z >= u_near: the
// shooter's own surface, through its centre, is not in its view), then each vertex
// is normalised onto the unit hemisphere and drawn at its (x, y); depth is
// its distance, projected separately so that depth order stays right (the
// chapter's listing 39-2). Polygons are tessellated on the CPU, since their
// edges project to curves that the rasteriser draws straight (the chapter's
// figure 39-5). A clipped edge lies on the plane and projects to an arc of the
// rim; its two ends are pushed out radially by 1 / cos(half the arc), so the
// straight edge between them passes outside the rim and the polygon covers
// the whole arc (nothing outside the unit disc is ever looked up).
// The side a facet shows the shooter is decided once per facet, from the
// facet's own plane (turned to agree with the primitive's outward normal),
// not per fragment from the curved surface's normal, which near a
// silhouette would name the far side.
#include "common/scene.glsl"

layout(triangles) in;
layout(triangle_strip, max_vertices = 4) out;

uniform float u_far;
uniform float u_near;
uniform vec3 u_origin;

in vec3 g_local[];
in vec3 g_world[];
flat in int g_primitive[];

out vec3 v_world;
flat out int v_primitive;
flat out int v_side;
flat out vec3 v_facing;          // the shown side's facet normal

int side;
vec3 facing;

void emit(vec3 local, vec3 world, float push) {
    float len = length(local);
    vec2 xy = len > 0.0 ? local.xy / len * push : vec2(1.0, 0.0);
    gl_Position = vec4(xy, 2.0 * len / u_far - 1.0, 1.0);
    v_world = world;
    v_primitive = g_primitive[0];
    v_side = side;
    v_facing = facing;
    EmitVertex();
}

void main() {
    vec3 centre = (g_world[0] + g_world[1] + g_world[2]) / 3.0;
    vec3 facet = cross(g_world[1] - g_world[0], g_world[2] - g_world[0]);
    if (dot(facet, geometric_normal(g_primitive[0], centre)) < 0.0) facet = -facet;
    side = dot(facet, u_origin - centre) >= 0.0 ? 0 : 1;
    facing = normalize(side == 0 ? facet : -facet);
    // Sutherland-Hodgman against z >= u_near: at most four vertices.
    vec3 local[4], world[4];
    bool cut[4] = bool[4](false, false, false, false);
    int n = 0;
    for (int i = 0; i < 3; ++i) {
        int j = (i + 1) % 3;
        vec3 a = g_local[i], b = g_local[j];
        bool a_in = a.z >= u_near, b_in = b.z >= u_near;
        if (a_in) {
            local[n] = a;
            world[n] = g_world[i];
            ++n;
        }
        if (a_in != b_in) {
            float s = (a.z - u_near) / (a.z - b.z);
            local[n] = mix(a, b, s);
            local[n].z = u_near;
            world[n] = mix(g_world[i], g_world[j], s);
            cut[n] = true;
            ++n;
        }
    }
    if (n < 3) return;
    // The clipped edge's arc: between the two cut vertices (if any).
    float push = 1.0;
    vec2 ends[2];
    int cuts = 0;
    for (int i = 0; i < n; ++i) {
        if (cut[i] && cuts < 2 && dot(local[i].xy, local[i].xy) > 0.0) ends[cuts++] = normalize(local[i].xy);
    }
    if (cuts == 2) push = 1.0 / max(cos(0.5 * acos(clamp(dot(ends[0], ends[1]), -1.0, 1.0))), 0.25);
    float p[4];
    for (int i = 0; i < 4; ++i) p[i] = cut[i] ? push : 1.0;
    // A strip of the fan 0, 1, 2 (, 3): 0, 1, n-1, 2.
    emit(local[0], world[0], p[0]);
    emit(local[1], world[1], p[1]);
    emit(local[n - 1], world[n - 1], p[n - 1]);
    if (n == 4) emit(local[2], world[2], p[2]);
    EndPrimitive();
}
