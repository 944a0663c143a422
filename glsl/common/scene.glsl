// The scene as textures (packed by src/scene/pack.rs) and the closest-hit and
// shadow queries over it, through a bounding volume hierarchy (src/scene/bvh.rs;
// the paper's ray tracer used a uniform grid, and its scenes are small enough
// for a loop over every primitive, but meshes are not).

// Scene defines (src/scene/pack.rs sets them for the scene last packed):
// - SCENE_KINDS, SCENE_MATERIALS, SCENE_LIGHTS: bit PRIM_*, MAT_*, LIGHT_*
//   set for each kind of primitive, material (on a shape) and light the
//   scene holds; SCENE_SHADING_NORMALS: 1 where a triangle has vertex
//   normals. The code of what the scene lacks is left out: llvmpipe runs
//   both sides of every branch under a lane mask, so code no lane takes
//   still costs its time.
// - SCENE_PRIMITIVE_BLOCK: the linear scan's primitives in a uniform block as
//   well. In the linear scan every lane reads the same primitive, which
//   llvmpipe loads once from a uniform block but gathers lane by lane from a
//   texture.
// - SCENE_BVH_BLOCK (its size in texels), BVH_BLOCK_ORDER_AT,
//   BVH_BLOCK_PRIMITIVES_AT: a mid-size scene's hierarchy, leaf order and
//   primitives in one uniform block as well, where the threaded walk reads
//   them. Lanes then read different texels, but a uniform block's gather
//   is a plain load a lane, cheaper than a texel fetch's.
#ifndef SCENE_KINDS
#define SCENE_KINDS 15
#endif
#ifndef SCENE_MATERIALS
#define SCENE_MATERIALS 31
#endif
#ifndef SCENE_LIGHTS
#define SCENE_LIGHTS 7
#endif
#ifndef SCENE_SHADING_NORMALS
#define SCENE_SHADING_NORMALS 1
#endif
#define SCENE_HAS(kind) (((SCENE_KINDS >> kind) & 1) != 0)
#define SCENE_HAS_MATERIAL(kind) (((SCENE_MATERIALS >> kind) & 1) != 0)
#define SCENE_HAS_LIGHT(kind) (((SCENE_LIGHTS >> kind) & 1) != 0)
// Whether any surface reflects other than diffusely (mirror, glass, metal).
#define SCENE_HAS_SPECULAR (SCENE_HAS_MATERIAL(MAT_MIRROR) || SCENE_HAS_MATERIAL(MAT_GLASS) || SCENE_HAS_MATERIAL(MAT_CONDUCTOR))
// Whether a surface may have a glossy lobe (a metal, if rough).
#define SCENE_HAS_GLOSSY SCENE_HAS_MATERIAL(MAT_CONDUCTOR)

#include "common/intersect.glsl"

uniform sampler2D u_primitives;  // PRIMITIVE_TEXELS a primitive, PRIMITIVES_PER_ROW a row
uniform isampler2D u_bvh_nodes;  // 2 texels a node, BVH_ROW_TEXELS a row
uniform isampler2D u_bvh_order;  // leaf position -> primitive, BVH_ROW_TEXELS a row
uniform sampler2D u_materials;   // MATERIAL_TEXELS a material
uniform sampler2D u_lights;      // LIGHT_TEXELS a light
uniform sampler2D u_normals;     // NORMAL_TEXELS a triangle with vertex normals, NORMALS_PER_ROW a row
uniform sampler2D u_light_triangles; // a texel an emissive triangle (area cdf, primitive)
uniform int u_primitive_count;
uniform int u_light_count;

// PRIM_*, MAT_*, LIGHT_* kind codes, the *_TEXELS row lengths and the BVH
// sizes are #defines from src/layout.rs, injected into every program.

#ifdef SCENE_PRIMITIVE_BLOCK
layout(std140, binding = SCENE_BLOCK_BINDING) uniform ScenePrimitives {
    vec4 scene_primitives[LINEAR_SCAN_MAX * PRIMITIVE_TEXELS];
};
#endif

#ifdef SCENE_BVH_BLOCK
layout(std140, binding = SCENE_BLOCK_BINDING) uniform SceneHierarchy {
    ivec4 scene_hierarchy[SCENE_BVH_BLOCK];
};
#endif

vec4 primitive_texel(int prim, int i) {
#ifdef SCENE_PRIMITIVE_BLOCK
    return scene_primitives[prim * PRIMITIVE_TEXELS + i];
#elif defined(SCENE_BVH_BLOCK)
    return intBitsToFloat(scene_hierarchy[BVH_BLOCK_PRIMITIVES_AT + prim * PRIMITIVE_TEXELS + i]);
#else
    ivec2 at = ivec2((prim % PRIMITIVES_PER_ROW) * PRIMITIVE_TEXELS + i, prim / PRIMITIVES_PER_ROW);
    return texelFetch(u_primitives, at, 0);
#endif
}

// The primitive's PRIM_* kind: a constant where the scene holds one kind.
int primitive_kind(int prim) {
    if (SCENE_KINDS == (1 << PRIM_SPHERE)) return PRIM_SPHERE;
    if (SCENE_KINDS == (1 << PRIM_CYLINDER)) return PRIM_CYLINDER;
    if (SCENE_KINDS == (1 << PRIM_PARALLELOGRAM)) return PRIM_PARALLELOGRAM;
    if (SCENE_KINDS == (1 << PRIM_TRIANGLE)) return PRIM_TRIANGLE;
    return int(primitive_texel(prim, 0).x);
}

// Whether a primitive of kind `kind` (primitive_kind) is a `k`: false at
// compile time where the scene holds no `k`, so the code it guards is left out.
bool primitive_kind_is(int kind, int k) { return SCENE_HAS(k) && kind == k; }

vec4 intersect_primitive_ray(int prim, SceneRay r) {
    int kind = primitive_kind(prim);
    vec4 a = primitive_texel(prim, 1);
    vec4 b = primitive_texel(prim, 2);
    if (primitive_kind_is(kind, PRIM_SPHERE)) return intersect_sphere(r.o, r.d, a.xyz, a.w);
    if (primitive_kind_is(kind, PRIM_CYLINDER))
        return intersect_cylinder(r.o, r.d, a.xyz, b.xyz, a.w, b.w);
    vec4 c = primitive_texel(prim, 3);
    if (primitive_kind_is(kind, PRIM_TRIANGLE)) return intersect_triangle(r, a.xyz, b.xyz, c.xyz);
    if (primitive_kind_is(kind, PRIM_PARALLELOGRAM)) return intersect_parallelogram(r.o, r.d, a.xyz, b.xyz, c.xyz);
    return NO_HIT;
}

vec4 intersect_primitive(int prim, vec3 o, vec3 d) {
    return intersect_primitive_ray(prim, scene_ray(o, d));
}

// The geometric normal of primitive `prim` at p: outward for spheres and
// cylinders, e1 x e2 for planar shapes (v1 - v0, v2 - v0 for triangles).
vec3 geometric_normal(int prim, vec3 p) {
    int kind = primitive_kind(prim);
    vec4 a = primitive_texel(prim, 1);
    vec4 b = primitive_texel(prim, 2);
    if (primitive_kind_is(kind, PRIM_SPHERE)) return normalize(p - a.xyz);
    if (primitive_kind_is(kind, PRIM_CYLINDER)) {
        vec3 r = p - a.xyz;
        return normalize(r - dot(r, b.xyz) * b.xyz);
    }
    vec3 c = primitive_texel(prim, 3).xyz;
    if (primitive_kind_is(kind, PRIM_TRIANGLE)) return normalize(cross(b.xyz - a.xyz, c - a.xyz));
    return normalize(cross(b.xyz, c));
}

// The hit point rebuilt from surface parameters, not from o + t d: its error then
// scales with the surface's coordinates, not with the ray's length (pbrt-v4, 6.8).
// Also returns the geometric normal.
vec3 surface_point(int prim, vec3 o, vec3 d, vec4 hit, out vec3 normal) {
    int kind = primitive_kind(prim);
    vec4 a = primitive_texel(prim, 1);
    vec4 b = primitive_texel(prim, 2);
    if (primitive_kind_is(kind, PRIM_SPHERE)) {
        vec3 p = o + hit.x * d;
        normal = normalize(p - a.xyz);
        return a.xyz + a.w * normal;
    }
    if (primitive_kind_is(kind, PRIM_CYLINDER)) {
        vec3 p = o + hit.x * d;
        vec3 on_axis = a.xyz + hit.y * b.xyz;
        vec3 r = p - on_axis;
        normal = normalize(r - dot(r, b.xyz) * b.xyz);
        return on_axis + a.w * normal;
    }
    vec3 c = primitive_texel(prim, 3).xyz;
    if (primitive_kind_is(kind, PRIM_TRIANGLE)) {
        normal = normalize(cross(b.xyz - a.xyz, c - a.xyz));
        return (1.0 - hit.y - hit.z) * a.xyz + hit.y * b.xyz + hit.z * c;
    }
    normal = normalize(cross(b.xyz, c));
    return a.xyz + hit.y * b.xyz + hit.z * c;
}

int primitive_material(int prim) { return int(primitive_texel(prim, 0).y); }

// The light whose emitting primitive this is (head .w = light + 1), or -1.
int primitive_light(int prim) { return int(primitive_texel(prim, 0).w) - 1; }

// ---- shading normals: a triangle's vertex normals, interpolated.

// Whether the primitive has vertex normals (head .z = record + 1, 0: none).
bool has_shading_normal(int prim) { return SCENE_SHADING_NORMALS != 0 && primitive_texel(prim, 0).z > 0.0; }

// The shading normal at p (a point of primitive prim, whose unit geometric
// normal is n): the vertex normals interpolated by p's barycentric weights
// and normalised, on n's side; n itself for a primitive without normals, or
// where the interpolated normal points to the other side of the face.
// src/reference/shading.rs is its twin.
vec3 shading_normal(int prim, vec3 p, vec3 n) {
    if (SCENE_SHADING_NORMALS == 0) return n;
    int record = int(primitive_texel(prim, 0).z) - 1;
    if (record < 0) return n;
    vec3 a = primitive_texel(prim, 1).xyz;
    vec3 e1 = primitive_texel(prim, 2).xyz - a;
    vec3 e2 = primitive_texel(prim, 3).xyz - a;
    vec3 q = p - a;
    vec3 c = cross(e1, e2);
    float inv = 1.0 / dot(c, c);
    float w1 = dot(cross(q, e2), c) * inv;
    float w2 = dot(cross(e1, q), c) * inv;
    ivec2 at = ivec2((record % NORMALS_PER_ROW) * NORMAL_TEXELS, record / NORMALS_PER_ROW);
    vec3 n0 = texelFetch(u_normals, at, 0).xyz;
    vec3 n1 = texelFetch(u_normals, at + ivec2(1, 0), 0).xyz;
    vec3 n2 = texelFetch(u_normals, at + ivec2(2, 0), 0).xyz;
    vec3 s = (1.0 - w1 - w2) * n0 + w1 * n1 + w2 * n2;
    float len = length(s);
    if (!(len > 0.0) || dot(s, n) <= 0.0) return n;
    return s / len;
}

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

// ---- BVH traversal over the threaded layout of src/scene/bvh.rs (nodes in
// depth-first order, each with its miss link). Three walks, by where the
// scene lives:
// - SCENE_LINEAR_SCAN (a scene whose walk would cost more): a loop over
//   every primitive;
// - SCENE_BVH_BLOCK (a hierarchy that fits a uniform block): the threaded
//   walk, no stack: a node whose box the ray enters leads to the next node
//   (an inner node's first child; a leaf's primitives are tested, then its
//   miss link), a missed one to its miss link;
// - otherwise (textures): the ordered walk with a stack, near child first.

ivec4 bvh_node_texel(int node, int which) {
    int i = 2 * node + which;
#ifdef SCENE_BVH_BLOCK
    return scene_hierarchy[i];
#else
    return texelFetch(u_bvh_nodes, ivec2(i % BVH_ROW_TEXELS, i / BVH_ROW_TEXELS), 0);
#endif
}

int bvh_leaf_primitive(int position) {
#ifdef SCENE_BVH_BLOCK
    return scene_hierarchy[BVH_BLOCK_ORDER_AT + position / 4][position % 4];
#else
    return texelFetch(u_bvh_order, ivec2(position % BVH_ROW_TEXELS, position / BVH_ROW_TEXELS), 0).x;
#endif
}

// BOX_ROBUST (src/layout.rs) widens the far distance of the slab test.
const float BOX_MISS = 1e30;

// Entry distance of the ray into the box (lo, hi), or BOX_MISS.
float box_entry(ivec4 lo, ivec4 hi, SceneRay r, float t_max) {
    vec3 t0 = (intBitsToFloat(lo.xyz) - r.o) * r.inv;
    vec3 t1 = (intBitsToFloat(hi.xyz) - r.o) * r.inv;
    vec3 near = min(t0, t1), far = max(t0, t1);
    float t_in = max(max(near.x, near.y), max(near.z, 0.0));
    float t_out = min(min(far.x, far.y), far.z) * BOX_ROBUST;
    return t_in <= min(t_out, t_max) ? t_in : BOX_MISS;
}

#ifdef PRIMITIVE_BOXES
// Imperfect visibility (IGI's VPL shadow rays, after Marques and Santos 4.1):
// every primitive stands for its bounding box. A box blocks the segment only
// where the segment passes through it with both ends outside, so the boxes
// of the primitives at the ends never block it.
uniform sampler2D u_primitive_boxes; // 2 texels a primitive: min, max
vec4 leaf_hit(int prim, SceneRay r) {
    ivec2 t = ivec2((2 * prim) % PRIMITIVE_BOX_ROW, (2 * prim) / PRIMITIVE_BOX_ROW);
    vec3 lo = texelFetch(u_primitive_boxes, t, 0).xyz;
    vec3 hi = texelFetch(u_primitive_boxes, t + ivec2(1, 0), 0).xyz;
    vec3 t0 = (lo - r.o) * r.inv, t1 = (hi - r.o) * r.inv;
    vec3 near = min(t0, t1), far = max(t0, t1);
    float t_in = max(max(near.x, near.y), near.z);
    float t_out = min(min(far.x, far.y), far.z);
    return t_in > 0.0 && t_in <= t_out ? vec4(t_out, 0.0, 0.0, 1.0) : NO_HIT;
}
#else
vec4 leaf_hit(int prim, SceneRay r) { return intersect_primitive_ray(prim, r); }
#endif

// Tests a leaf's primitives (its texel's w: -(first x LEAF_COUNT_SPAN +
// count)) against the ray, keeping the closest hit before best.x.
void bvh_leaf(int leaf, SceneRay r, inout vec4 best, inout int hit) {
    int first = (-leaf) / LEAF_COUNT_SPAN;
    int end = first + (-leaf) % LEAF_COUNT_SPAN;
    for (int i = first; i < end; ++i) {
        int prim = bvh_leaf_primitive(i);
        vec4 h = leaf_hit(prim, r);
        if (h.w > 0.0 && h.x < best.x) {
            best = h;
            hit = prim;
        }
    }
}

// The closest primitive hit before best.x (set by the caller), or -1; with
// any_hit, the first found. best becomes its record. (With PRIMITIVE_BOXES a
// "hit" is a box passed through, at its exit distance: for occlusion only.)
int bvh_trace(SceneRay r, bool any_hit, inout vec4 best) {
    if (u_primitive_count == 0) return -1;
    int hit = -1;
#if defined(SCENE_LINEAR_SCAN)
    // A scene whose walk costs more than a loop (FlatBvh::loses_to_a_loop,
    // src/scene/bvh.rs): every primitive in turn, no stack, no boxes.
    for (int prim = 0; prim < u_primitive_count; ++prim) {
        vec4 h = leaf_hit(prim, r);
        if (h.w > 0.0 && h.x < best.x) {
            best = h;
            hit = prim;
            if (any_hit) return hit;
        }
    }
#elif defined(SCENE_BVH_BLOCK)
    // The threaded walk: the next node, or the miss link; no stack.
    int node = 0;
    while (node >= 0) {
        ivec4 lo = bvh_node_texel(node, 0), hi = bvh_node_texel(node, 1);
        bool enter = box_entry(lo, hi, r, best.x) < BOX_MISS;
        if (enter && lo.w < 0) {
            bvh_leaf(lo.w, r, best, hit);
            if (any_hit && hit >= 0) return hit;
        }
        node = enter && lo.w == 0 ? node + 1 : hi.w;
    }
#else
    // The ordered walk: an inner node's children are the next node and that
    // one's miss link; the nearer is entered first, the farther pushed with
    // its entry distance and dropped unread once a closer hit is known.
    // A node is (index, its leaf word).
    ivec4 lo = bvh_node_texel(0, 0), hi = bvh_node_texel(0, 1);
    if (box_entry(lo, hi, r, best.x) == BOX_MISS) return -1;
    ivec2 node = ivec2(0, lo.w);
    ivec2 stack_node[BVH_STACK];
    float stack_entry[BVH_STACK];
    int depth = 0;
    for (;;) {
        if (node.y < 0) {
            bvh_leaf(node.y, r, best, hit);
            if (any_hit && hit >= 0) return hit;
        } else {
            int a = node.x + 1;
            ivec4 l0 = bvh_node_texel(a, 0), l1 = bvh_node_texel(a, 1);
            int b = l1.w;
            ivec4 r0 = bvh_node_texel(b, 0), r1 = bvh_node_texel(b, 1);
            float tl = box_entry(l0, l1, r, best.x);
            float tr = box_entry(r0, r1, r, best.x);
            if (min(tl, tr) < BOX_MISS) {
                bool right_first = tr < tl;
                if (max(tl, tr) < BOX_MISS) {
                    stack_node[depth] = right_first ? ivec2(a, l0.w) : ivec2(b, r0.w);
                    stack_entry[depth] = max(tl, tr);
                    ++depth; // at most the tree's depth - 1 (checked on the host)
                }
                node = right_first ? ivec2(b, r0.w) : ivec2(a, l0.w);
                continue;
            }
        }
        while (depth > 0 && stack_entry[depth - 1] >= best.x) --depth;
        if (depth == 0) break;
        --depth;
        node = stack_node[depth];
    }
#endif
    return hit;
}

// Closest hit along a unit direction: returns the primitive or -1, with its record.
int closest_hit(vec3 o, vec3 d, out vec4 best) {
    best = NO_HIT;
    return bvh_trace(scene_ray(o, d), false, best);
}

// Whether anything blocks the segment from o toward o + t_max d (d unit).
// Glass blocks too: light through glass arrives as caustic photons, not here.
bool occluded(vec3 o, vec3 d, float t_max) {
    vec4 h = vec4(t_max, 0.0, 0.0, 0.0);
    return bvh_trace(scene_ray(o, d), true, h) >= 0;
}

// Whether anything blocks a shadow ray from `origin`, already lifted off its
// own surface, to the point q on another surface: aimed at q itself, so it
// meets q's plane at q whatever the two surfaces' angle, and stopped short
// of q's surface by its offset scale.
bool occluded_toward(vec3 origin, vec3 q) {
    vec3 to = q - origin;
    float reach = length(to);
    return occluded(origin, to / reach, reach - 2.0 * offset_scale(q));
}

vec4 material_texel(int m, int i) { return texelFetch(u_materials, ivec2(i, m), 0); }
int material_kind(int m) { return int(material_texel(m, 0).x); }
vec4 light_texel(int l, int i) { return texelFetch(u_lights, ivec2(i, l), 0); }

// The light's LIGHT_* kind: a constant where the scene holds one kind of light.
int light_kind(int l) {
    if (SCENE_LIGHTS == (1 << LIGHT_AREA)) return LIGHT_AREA;
    if (SCENE_LIGHTS == (1 << LIGHT_POINT)) return LIGHT_POINT;
    if (SCENE_LIGHTS == (1 << LIGHT_TRIANGLES)) return LIGHT_TRIANGLES;
    return int(light_texel(l, 0).x);
}

// Whether a light of kind `kind` (light_kind) is a `k`: false at compile
// time where the scene has no light of kind `k`.
bool light_kind_is(int kind, int k) { return SCENE_HAS_LIGHT(k) && kind == k; }

vec4 light_triangle_texel(int i) {
    return texelFetch(u_light_triangles, ivec2(i % LIGHT_TRIANGLE_ROW_TEXELS, i / LIGHT_TRIANGLE_ROW_TEXELS), 0);
}

// A point of a LIGHT_TRIANGLES light l, uniform over its area, from two
// uniforms: u1 picks a triangle in proportion to its area (binary search of
// the light's cumulative areas) and, rescaled within the triangle's share,
// gives with u2 a uniform point in it. Also its front-face unit normal and
// its primitive. (The pdf is 1 / the light's area: row 1 .z.)
// src/reference/photon.rs `sample_light_triangle` is its twin.
vec3 sample_light_triangle(int l, float u1, float u2, out vec3 normal, out int prim) {
    vec4 range = light_texel(l, 1); // first texel, count, area
    int first = int(range.x);
    int lo = 0, hi = int(range.y) - 1;
    while (lo < hi) {
        int mid = (lo + hi) / 2;
        if (u1 < light_triangle_texel(first + mid).x) hi = mid;
        else lo = mid + 1;
    }
    vec4 entry = light_triangle_texel(first + lo);
    float below = lo > 0 ? light_triangle_texel(first + lo - 1).x : 0.0;
    float u = clamp((u1 - below) / (entry.x - below), 0.0, 1.0);
    prim = int(entry.y);
    vec3 a = primitive_texel(prim, 1).xyz;
    vec3 b = primitive_texel(prim, 2).xyz;
    vec3 c = primitive_texel(prim, 3).xyz;
    normal = normalize(cross(b - a, c - a));
    float s = sqrt(u);
    return (1.0 - s) * a + (u2 * s) * b + (s - u2 * s) * c;
}

// An area light (a parallelogram, or a LIGHT_TRIANGLES light's emissive
// triangles): a parallelogram's corner, edges and normal, and the light's
// area (its pdf over area is 1 / area), read once, not once per sample.
struct AreaLight { bool triangles; vec3 a, e1, e2, normal; float area; };

AreaLight area_light(int l) {
    vec4 head = light_texel(l, 0);
    AreaLight L;
    L.triangles = light_kind_is(light_kind(l), LIGHT_TRIANGLES);
    L.a = light_texel(l, 1).xyz;
    L.e1 = light_texel(l, 2).xyz;
    L.e2 = light_texel(l, 3).xyz;
    L.normal = head.yzw;
    L.area = L.triangles ? light_texel(l, 1).z : length(cross(L.e1, L.e2));
    return L;
}

// A point of area light l from two uniforms (su, sv), the light's unit
// normal there and the primitive it lies on (a LIGHT_TRIANGLES light's
// triangle, picked with su; -1 for a parallelogram light).
vec3 area_light_point(int l, AreaLight L, float su, float sv, out vec3 light_normal,
                      out int prim) {
    if (L.triangles) return sample_light_triangle(l, su, sv, light_normal, prim);
    prim = -1;
    light_normal = L.normal;
    return L.a + su * L.e1 + sv * L.e2;
}

vec3 area_light_point(int l, AreaLight L, float su, float sv, out vec3 light_normal) {
    int prim;
    return area_light_point(l, L, su, sv, light_normal, prim);
}
