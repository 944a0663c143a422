// The scene as textures (packed by src/scene/pack.rs) and the closest-hit and
// shadow queries over all of it: a loop over every primitive, as in the paper.
#include "common/intersect.glsl"

uniform sampler2D u_primitives; // PRIMITIVE_TEXELS a primitive, one row each
uniform sampler2D u_materials;  // MATERIAL_TEXELS a material
uniform sampler2D u_lights;     // LIGHT_TEXELS a light
uniform int u_primitive_count;
uniform int u_light_count;

// PRIM_*, MAT_*, LIGHT_* kind codes and the *_TEXELS row lengths are
// #defines from src/layout.rs, injected into every program.

vec4 primitive_texel(int prim, int i) { return texelFetch(u_primitives, ivec2(i, prim), 0); }

vec4 intersect_primitive(int prim, vec3 o, vec3 d) {
    vec4 head = primitive_texel(prim, 0);
    int kind = int(head.x);
    vec4 a = primitive_texel(prim, 1);
    vec4 b = primitive_texel(prim, 2);
    if (kind == PRIM_SPHERE) return intersect_sphere(o, d, a.xyz, a.w);
    if (kind == PRIM_CYLINDER) return intersect_cylinder(o, d, a.xyz, b.xyz, a.w, b.w);
    vec4 c = primitive_texel(prim, 3);
    return intersect_planar(o, d, a.xyz, b.xyz, c.xyz, kind == PRIM_TRIANGLE);
}

// The hit point rebuilt from surface parameters, not from o + t d: its error then
// scales with the surface's coordinates, not with the ray's length (pbrt-v4, 6.8).
// Also returns the geometric normal (outward for spheres and cylinders,
// e1 x e2 for planar shapes).
vec3 surface_point(int prim, vec3 o, vec3 d, vec4 hit, out vec3 normal) {
    vec4 head = primitive_texel(prim, 0);
    int kind = int(head.x);
    vec4 a = primitive_texel(prim, 1);
    vec4 b = primitive_texel(prim, 2);
    if (kind == PRIM_SPHERE) {
        vec3 p = o + hit.x * d;
        normal = normalize(p - a.xyz);
        return a.xyz + a.w * normal;
    }
    if (kind == PRIM_CYLINDER) {
        vec3 p = o + hit.x * d;
        vec3 on_axis = a.xyz + hit.y * b.xyz;
        vec3 r = p - on_axis;
        normal = normalize(r - dot(r, b.xyz) * b.xyz);
        return on_axis + a.w * normal;
    }
    vec4 c = primitive_texel(prim, 3);
    normal = normalize(cross(b.xyz, c.xyz));
    return a.xyz + hit.y * b.xyz + hit.z * c.xyz;
}

int primitive_material(int prim) { return int(primitive_texel(prim, 0).y); }

// Distance to move a ray origin off a surface at p: relative to p's magnitude
// (float error in p scales with it) plus a floor relative to the scene's size.
uniform float u_offset_floor;
const float OFFSET_RELATIVE = 3.814697265625e-6; // 2^-18: 32 ulp of |p|

float offset_scale(vec3 p) {
    vec3 ap = abs(p);
    return OFFSET_RELATIVE * max(ap.x, max(ap.y, ap.z)) + u_offset_floor;
}

// Moves p off the surface with normal n to the side the new direction leaves by.
vec3 offset_origin(vec3 p, vec3 n, vec3 dir) {
    float s = offset_scale(p);
    return p + (dot(dir, n) >= 0.0 ? s : -s) * n;
}

// Closest hit along a unit direction: returns the primitive or -1, with its record.
int closest_hit(vec3 o, vec3 d, out vec4 best) {
    best = NO_HIT;
    int best_prim = -1;
    for (int i = 0; i < u_primitive_count; ++i) {
        vec4 h = intersect_primitive(i, o, d);
        if (h.w > 0.0 && h.x < best.x) {
            best = h;
            best_prim = i;
        }
    }
    return best_prim;
}

// Whether anything blocks the segment from o toward o + t_max d (d unit).
// Glass blocks too: light through glass arrives as caustic photons, not here.
bool occluded(vec3 o, vec3 d, float t_max) {
    for (int i = 0; i < u_primitive_count; ++i) {
        vec4 h = intersect_primitive(i, o, d);
        if (h.w > 0.0 && h.x < t_max) return true;
    }
    return false;
}

vec4 material_texel(int m, int i) { return texelFetch(u_materials, ivec2(i, m), 0); }
int material_kind(int m) { return int(material_texel(m, 0).x); }
vec4 light_texel(int l, int i) { return texelFetch(u_lights, ivec2(i, l), 0); }
