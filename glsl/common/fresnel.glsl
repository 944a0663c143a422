// Exact unpolarised Fresnel reflectance of a smooth dielectric.
// cos_i > 0 is the cosine to the normal on the incident side, eta = n_i / n_t.
// Returns 1 on total internal reflection; cos_t gets the transmitted cosine.
float fresnel_dielectric(float cos_i, float eta, out float cos_t) {
    float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) {
        cos_t = 0.0;
        return 1.0;
    }
    cos_t = sqrt(1.0 - sin2_t);
    float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}
