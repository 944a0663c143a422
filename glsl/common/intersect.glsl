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

// Parallelogram corner + u e1 + v e2 (u, v in [0, 1]) and triangle (u, v >= 0,
// u + v <= 1), both by Moller-Trumbore.
vec4 intersect_planar(vec3 o, vec3 d, vec3 corner, vec3 e1, vec3 e2, bool triangle) {
    vec3 pvec = cross(d, e2);
    float det = dot(e1, pvec);
    if (det == 0.0) return NO_HIT;
    float inv_det = 1.0 / det;
    vec3 tvec = o - corner;
    float u = dot(tvec, pvec) * inv_det;
    if (u < 0.0 || u > 1.0) return NO_HIT;
    vec3 qvec = cross(tvec, e1);
    float v = dot(d, qvec) * inv_det;
    if (v < 0.0 || (triangle ? u + v > 1.0 : v > 1.0)) return NO_HIT;
    float t = dot(e2, qvec) * inv_det;
    if (t <= 0.0) return NO_HIT;
    return vec4(t, u, v, 1.0);
}
