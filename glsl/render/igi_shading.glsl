// Instant global illumination's shading points and surface continuity,
// shared by the gather, the discontinuity buffer and the upsampling.

// The full-resolution pixel whose first hit is shading point q: the pixel
// itself, or (downsampled by scale) the middle of q's scale x scale block.
ivec2 shading_pixel(ivec2 q, int scale, ivec2 full) {
    return min(q * scale + scale / 2, full - 1);
}

// Whether the hit y lies on the surface of the hit x (normal nx, at eye
// distance d): off x's tangent plane by at most VPL_DEPTH_TOLERANCE of d.
bool continues_surface(vec3 x, vec3 nx, float d, vec3 y) {
    return abs(dot(y - x, nx)) <= VPL_DEPTH_TOLERANCE * d;
}
