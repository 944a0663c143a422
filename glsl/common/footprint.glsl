// A photon's footprint (Fabianowski and Dingliana 2009, section 4): the
// ellipse p + alpha a + beta b, alpha^2 + beta^2 <= 1, whose semi-axes a and
// b lie on the surface the photon hit (a x b facing the side it came from),
// with depth along the normal: the paper's skewed ellipsoid, alpha^2 +
// beta^2 + gamma^2 <= 1 for x = p + alpha a + beta b + gamma c, c along the
// normal and FOOTPRINT_THICKNESS of the longer of a and b; or, by default,
// the curved footprint, which holds x where its projection lies in the
// ellipse and x lies as near the plane as a curved surface through p would
// (footprint_distance2). On a ball the ellipsoid, thinning to nothing at its
// rim, lets the rim's points out, and the power they should have had (the
// kernel is normalised over the whole ellipse) is lost.
// Its records, in Morton order
// (footprint i at texel (i mod width, i / width) of textures of that width):
//   footprint 0: centre p, w = area of the ellipse, pi |a x b|;
//   footprint 1: a, w = 1 if the photon had been reflected diffusely;
//   footprint 2: b, w = |c|;
//   footprint 3: power, w = 1 for a caustic footprint left out (area 0), else 0.
// src/twins/differentials.rs is its twin.

ivec2 footprint_texel(int i, int width) {
    return ivec2(i % width, i / width);
}

// The normal semi-axis c of semi-axes a, b with |c| = thickness.
vec3 footprint_normal_axis(vec3 a, vec3 b, float thickness) {
    return normalize(cross(a, b)) * thickness;
}

// Half the extent of the footprint along each world axis: the ellipsoid's,
// sqrt(a_i^2 + b_i^2 + c_i^2); the curved footprint's, the ellipse's
// sqrt(a_i^2 + b_i^2) plus its deepest reach along the normal (below).
vec3 footprint_half_extent(vec3 a, vec3 b, vec3 c, bool curved) {
    if (!curved) return sqrt(a * a + b * b + c * c);
    float tan_half_max = sqrt((1.0 - COVERAGE_NORMAL_COS) / (1.0 + COVERAGE_NORMAL_COS));
    float depth = length(c) + tan_half_max * sqrt(dot(a, a) + dot(b, b));
    return sqrt(a * a + b * b) + abs(normalize(c)) * depth;
}

// The squared distance in the footprint of query point x (unit normal nq):
// alpha^2 + beta^2 + gamma^2 for the ellipsoid; for the curved footprint
// alpha^2 + beta^2 of x's projection onto the ellipse's plane, where nq
// tilts from the footprint's normal n by an angle phi of cosine at least
// COVERAGE_NORMAL_COS and x lies no farther from the plane than |c| +
// rho tan(phi / 2), rho its distance from p along the plane: a sphere
// tangent to the plane at p lies exactly there (rho = R sin phi, depth
// R (1 - cos phi)), a cylinder within it, while the other wall at a
// corner, tilted by a right angle, does not count; across a crease that
// turns by less than 60 degrees (a bevel, a faceted mesh) the face beyond
// counts near the crease, as a curved surface's would. Above 1 outside
// either.
float footprint_distance2(vec3 x, vec3 nq, vec3 p, vec3 a, vec3 b, vec3 c, bool curved) {
    vec3 e = x - p;
    vec3 bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
    float det = dot(a, bc);
    vec3 u = vec3(dot(bc, e), dot(ca, e), dot(ab, e)) / det;
    if (!curved) return dot(u, u);
    float thickness = length(c);
    float cos_phi = dot(c, nq) / thickness;
    if (!(cos_phi >= COVERAGE_NORMAL_COS)) return 2.0;
    float tan_half = sqrt(max(0.0, 1.0 - cos_phi * cos_phi)) / (1.0 + cos_phi);
    float rho = length(u.x * a + u.y * b);
    return abs(u.z) * thickness <= thickness + rho * tan_half ? dot(u.xy, u.xy) : 2.0;
}
