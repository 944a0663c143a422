// The form factor from a point x with unit normal n to a polygon (its
// vertices v[0..count), in either winding; a non-planar loop stands for the
// surface it bounds, seen whole from its front), by Lambert's formula:
// F = |sum_i gamma_i n . (a_i x a_i+1) / |a_i x a_i+1|| / 2 pi, a_i the unit
// vectors from x to the vertices and gamma_i the angle between them, after
// clipping the polygon to x's upper half-space. Exact for any distance, where
// the oriented disc's A cos cos / (pi d^2 + A) is not.
// src/reference/radiosity.rs `polygon_form_factor` is its twin.
const int CLIPPED = SHOOTER_OUTLINE + 1;

float polygon_form_factor(vec3 x, vec3 n, vec3 v[SHOOTER_OUTLINE], int count) {
    vec3 c[CLIPPED];
    int m = 0;
    for (int k = 0; k < count; ++k) {
        vec3 a = v[k] - x;
        vec3 b = v[(k + 1) % count] - x;
        float da = dot(a, n), db = dot(b, n);
        if (da > 0.0) c[m++] = a;
        if ((da > 0.0) != (db > 0.0)) c[m++] = a + (da / (da - db)) * (b - a);
    }
    if (m < 3) return 0.0;
    float sum = 0.0;
    for (int k = 0; k < m; ++k) {
        vec3 a = normalize(c[k]);
        vec3 b = normalize(c[(k + 1) % m]);
        vec3 axb = cross(a, b);
        float s = length(axb);
        if (s > 0.0) sum += atan(s, dot(a, b)) * dot(n, axb) / s;
    }
    return abs(sum) / (2.0 * PI);
}
