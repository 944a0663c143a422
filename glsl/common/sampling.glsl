// Direction sampling. src/sampling.rs mirrors these line for line.

// An orthonormal basis around a unit n (Duff et al. 2017, branchless).
void basis_around(vec3 n, out vec3 t, out vec3 b) {
    float s = n.z >= 0.0 ? 1.0 : -1.0;
    float a = -1.0 / (s + n.z);
    float c = n.x * n.y * a;
    t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
    b = vec3(c, s + n.y * n.y * a, -n.y);
}

// Cosine-distributed direction about n from two uniforms in [0, 1).
vec3 sample_cosine(vec3 n, float u1, float u2) {
    float r = sqrt(u1);
    float phi = 2.0 * PI * u2;
    vec3 t, b;
    basis_around(n, t, b);
    return normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(max(0.0, 1.0 - u1)) * n);
}

// Uniform direction on the sphere.
vec3 sample_sphere(float u1, float u2) {
    float z = 1.0 - 2.0 * u1;
    float r = sqrt(max(0.0, 1.0 - z * z));
    float phi = 2.0 * PI * u2;
    return vec3(r * cos(phi), r * sin(phi), z);
}
