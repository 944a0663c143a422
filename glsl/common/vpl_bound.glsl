// Marques and Santos's bound f(0.8 m, 1.2 m, d) of IGI's geometry term: 0
// below 0.8 m, 1 above 1.2 m and quadratic between, ((d - 0.8 m) / 0.4 m)^2;
// 1 everywhere when m <= 0 (unbounded). The VPL gather multiplies by it, and
// the bias compensation's gather rays weight by what it leaves out, 1 - f.
// src/twins/igi.rs `bound` is the twin.
float vpl_bound(float d, float m) {
    if (m <= 0.0) return 1.0;
    float s = clamp((d - 0.8 * m) / (0.4 * m), 0.0, 1.0);
    return s * s;
}
