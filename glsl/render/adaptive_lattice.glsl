// Adaptive sampling (section 4.5): the corners of the coarser lattice
// (stride 2 * stride) around pixel p, and p's bilinear weight for each. Past
// the image's last lattice row or column the near corners carry it all, and a
// zero weight marks a corner not to read. Shared by the plan
// (render/adaptive_plan.glsl) and adaptive SPPM's fill (sppm_adaptive_fill.frag).
void lattice_corners(ivec2 p, int stride, ivec2 size, out ivec2 corners[4], out float weights[4]) {
    int s2 = 2 * stride;
    ivec2 c0 = (p / s2) * s2;
    ivec2 c1 = c0 + s2;
    float fx = c1.x < size.x ? float(p.x - c0.x) / float(s2) : 0.0;
    float fy = c1.y < size.y ? float(p.y - c0.y) / float(s2) : 0.0;
    for (int i = 0; i < 4; ++i) {
        weights[i] = ((i & 1) != 0 ? fx : 1.0 - fx) * ((i & 2) != 0 ? fy : 1.0 - fy);
        corners[i] = ivec2((i & 1) != 0 ? c1.x : c0.x, (i & 2) != 0 ? c1.y : c0.y);
    }
}
