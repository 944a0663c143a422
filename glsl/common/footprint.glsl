// A photon's footprint (Fabianowski and Dingliana 2009, section 4): the
// skewed ellipsoid x = p + alpha a + beta b + gamma c, alpha^2 + beta^2 +
// gamma^2 <= 1, whose semi-axes a and b lie on the surface the photon hit
// (a x b facing the side it came from) and c along the normal,
// FOOTPRINT_THICKNESS of the longer of a and b. Its records, in Morton order
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

// Half the extent of the ellipsoid along each world axis.
vec3 footprint_half_extent(vec3 a, vec3 b, vec3 c) {
    return sqrt(a * a + b * b + c * c);
}

// The query point's ellipsoid coordinates squared (alpha^2 + beta^2 +
// gamma^2): <= 1 inside.
float footprint_distance2(vec3 x, vec3 p, vec3 a, vec3 b, vec3 c) {
    vec3 e = x - p;
    vec3 bc = cross(b, c), ca = cross(c, a), ab = cross(a, b);
    float det = dot(a, bc);
    vec3 u = vec3(dot(bc, e), dot(ca, e), dot(ab, e)) / det;
    return dot(u, u);
}
