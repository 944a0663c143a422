// Ray-primitive intersections. Each returns vec4(t, u, v, hit): t along a unit
// direction, (u, v) surface parameters to rebuild the hit point from, hit = 1 or 0.
// src/reference/intersect.rs holds the same formulas in Rust; tests compare them.

const vec4 NO_HIT = vec4(1e30, 0.0, 0.0, 0.0);

// Sphere by the stable quadratic (Haines et al., Ray Tracing Gems ch. 7): the
// discriminant from the closest-approach vector avoids cancellation, and the
// second root comes from c / q, not from a difference of near-equal numbers.
vec4 intersect_sphere(vec3 o, vec3 d, vec3 center, float radius) {
    vec3 f = o - center;
    float b = -dot(f, d);
    vec3 l = f + b * d;
    float disc = radius * radius - dot(l, l);
    if (disc < 0.0) return NO_HIT;
    float c = dot(f, f) - radius * radius;
    float q = b + (b >= 0.0 ? sqrt(disc) : -sqrt(disc));
    float t0 = q != 0.0 ? c / q : 0.0;
    float t1 = q;
    float tn = min(t0, t1), tf = max(t0, t1);
    float t = tn > 0.0 ? tn : tf;
    if (t <= 0.0) return NO_HIT;
    return vec4(t, 0.0, 0.0, 1.0);
}

// Open cylinder (no caps): the sphere's method in the plane across the axis;
// the discriminant as r^2 |d_perp|^2 - |f_perp x d_perp|^2, free of cancellation.
// u = height of the hit along the axis.
vec4 intersect_cylinder(vec3 o, vec3 d, vec3 base, vec3 axis, float radius, float height) {
    vec3 f = o - base;
    vec3 fp = f - dot(f, axis) * axis;
    vec3 dp = d - dot(d, axis) * axis;
    float a = dot(dp, dp);
    if (a < 1e-12) return NO_HIT; // parallel to the axis: never meets the wall
    vec3 cr = cross(fp, dp);
    float disc = radius * radius * a - dot(cr, cr);
    if (disc < 0.0) return NO_HIT;
    float b = -dot(fp, dp);
    float c = dot(fp, fp) - radius * radius;
    float q = b + (b >= 0.0 ? sqrt(disc) : -sqrt(disc));
    float ta = q / a;
    float tb = q != 0.0 ? c / q : 0.0;
    float tn = min(ta, tb), tf = max(ta, tb);
    float hn = dot(f + tn * d, axis);
    if (tn > 0.0 && hn >= 0.0 && hn <= height) return vec4(tn, hn, 0.0, 1.0);
    float hf = dot(f + tf * d, axis);
    if (tf > 0.0 && hf >= 0.0 && hf <= height) return vec4(tf, hf, 0.0, 1.0);
    return NO_HIT;
}

// Parallelogram corner + u e1 + v e2 (u, v in [0, 1]) by Moller-Trumbore.
// (Triangles take the watertight test below.)
vec4 intersect_parallelogram(vec3 o, vec3 d, vec3 corner, vec3 e1, vec3 e2) {
    vec3 pvec = cross(d, e2);
    float det = dot(e1, pvec);
    if (det == 0.0) return NO_HIT;
    float inv_det = 1.0 / det;
    vec3 tvec = o - corner;
    float u = dot(tvec, pvec) * inv_det;
    if (u < 0.0 || u > 1.0) return NO_HIT;
    vec3 qvec = cross(tvec, e1);
    float v = dot(d, qvec) * inv_det;
    if (v < 0.0 || v > 1.0) return NO_HIT;
    float t = dot(e2, qvec) * inv_det;
    if (t <= 0.0) return NO_HIT;
    return vec4(t, u, v, 1.0);
}

// A ray prepared once for the watertight triangle test (Woop, Benthin and Wald,
// JCGT 2013): axes permuted so z is the direction's largest component (k), and
// the shear and scale that take the direction to +z (s). inv = 1 / d for box
// tests, with zero components replaced by a huge number of the same sign.
struct SceneRay { vec3 o; vec3 d; vec3 inv; ivec3 k; vec3 s; };

SceneRay scene_ray(vec3 o, vec3 d) {
    SceneRay r;
    r.o = o;
    r.d = d;
    for (int i = 0; i < 3; ++i)
        r.inv[i] = abs(d[i]) < 1e-30 ? (d[i] < 0.0 ? -1e30 : 1e30) : 1.0 / d[i];
#ifdef SCENE_HAS // compiled for a scene (common/scene.glsl): k and s serve triangles only
    if (!SCENE_HAS(PRIM_TRIANGLE)) return r;
#endif
    vec3 a = abs(d);
    int kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
    int kx = kz == 2 ? 0 : kz + 1;
    int ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0) { int swap = kx; kx = ky; ky = swap; } // keeps the winding
    r.k = ivec3(kx, ky, kz);
    float sz = 1.0 / d[kz];
    r.s = vec3(d[kx] * sz, d[ky] * sz, sz);
    return r;
}

// a b - c d with its exact sign. `precise` forbids fusing into an fma, which
// would make the two triangles of a shared edge round differently; a float
// result of 0 is recomputed in double, where the products are exact.
float edge_function(float a, float b, float c, float d) {
    precise float e = a * b - c * d;
    if (e == 0.0) e = float(double(a) * double(b) - double(c) * double(d));
    return e;
}

// Triangle v0 v1 v2, watertight: a ray through a shared edge or vertex hits
// at least one of the triangles around it. (u, v) are the barycentric weights
// of v1 and v2.
vec4 intersect_triangle(SceneRay r, vec3 v0, vec3 v1, vec3 v2) {
    vec3 a = v0 - r.o, b = v1 - r.o, c = v2 - r.o;
    float ax = a[r.k.x] - r.s.x * a[r.k.z], ay = a[r.k.y] - r.s.y * a[r.k.z];
    float bx = b[r.k.x] - r.s.x * b[r.k.z], by = b[r.k.y] - r.s.y * b[r.k.z];
    float cx = c[r.k.x] - r.s.x * c[r.k.z], cy = c[r.k.y] - r.s.y * c[r.k.z];
    float u = edge_function(cx, by, cy, bx);
    float v = edge_function(ax, cy, ay, cx);
    float w = edge_function(bx, ay, by, ax);
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return NO_HIT;
    float det = u + v + w;
    if (det == 0.0) return NO_HIT;
    float t_scaled = u * (r.s.z * a[r.k.z]) + v * (r.s.z * b[r.k.z]) + w * (r.s.z * c[r.k.z]);
    if ((det < 0.0 ? -t_scaled : t_scaled) <= 0.0) return NO_HIT;
    float inv_det = 1.0 / det;
    return vec4(t_scaled * inv_det, v * inv_det, w * inv_det, 1.0);
}
