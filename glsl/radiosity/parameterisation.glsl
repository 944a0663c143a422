// Each primitive's (u, v) in [0, 1)^2, the parameterisation its patch's
// elements are laid out by (src/render/radiosity.rs `element_point` is its
// inverse): a parallelogram's edge coordinates, a triangle's barycentric
// (b1, b2) (texels with u + v > 1 hold no element), a sphere's longitude and
// colatitude about y, a cylinder's angle and height.
vec2 patch_uv(int prim, vec3 p) {
    int kind = int(primitive_texel(prim, 0).x);
    vec4 a = primitive_texel(prim, 1);
    vec4 b = primitive_texel(prim, 2);
    if (kind == PRIM_SPHERE) {
        vec3 d = normalize(p - a.xyz);
        float phi = atan(d.z, d.x);
        if (phi < 0.0) phi += 2.0 * PI;
        return vec2(phi / (2.0 * PI), acos(clamp(d.y, -1.0, 1.0)) / PI);
    }
    if (kind == PRIM_CYLINDER) {
        vec3 axis = b.xyz;
        vec3 t, s;
        basis_around(axis, t, s);
        vec3 r = p - a.xyz;
        float phi = atan(dot(r, s), dot(r, t));
        if (phi < 0.0) phi += 2.0 * PI;
        return vec2(phi / (2.0 * PI), clamp(dot(r, axis) / b.w, 0.0, 1.0));
    }
    vec3 c = primitive_texel(prim, 3).xyz;
    vec3 e1 = kind == PRIM_TRIANGLE ? b.xyz - a.xyz : b.xyz;
    vec3 e2 = kind == PRIM_TRIANGLE ? c - a.xyz : c;
    vec3 q = p - a.xyz;
    vec3 n = cross(e1, e2);
    float inv = 1.0 / dot(n, n);
    return vec2(dot(cross(q, e2), n) * inv, dot(cross(e1, q), n) * inv);
}
