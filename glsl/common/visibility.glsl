// Whether a photon at p may light the query point x (normal nf facing the
// eye): nothing blocks the segment between them. Both ends are lifted along
// nf by a tenth of their distance (plus the ray offset), so the chord of a
// curved surface, which dips below it by d^2 / (8 R), is not blocked by the
// surface itself for curvature radii R above 1.25 d; a wall lower than the
// lift does not block either. src/reference/knn.rs (photon_visible) is the twin.
#include "common/scene.glsl"

bool photon_visible(vec3 x, vec3 nf, vec3 p) {
    float dist = distance(x, p);
    vec3 a = x + nf * (0.1 * dist + offset_scale(x));
    vec3 b = p + nf * (0.1 * dist + offset_scale(p));
    vec3 d = b - a;
    float len = length(d);
    if (len <= 0.0) return true;
    return !occluded(a, d / len, 0.999 * len);
}
