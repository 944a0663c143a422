//! Sampling in plain Rust, as glsl/common/sampling.glsl does it: directions on
//! the sphere and the cosine hemisphere (measure-preserving maps of the unit
//! square, which projection maps rely on), and strata for N samples.

use glam::Vec3;

const PI: f32 = std::f32::consts::PI;

/// Two unit vectors completing `n` (unit) to an orthonormal basis
/// (Duff et al. 2017, branchless).
pub fn basis_around(n: Vec3) -> (Vec3, Vec3) {
    let s = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (s + n.z);
    let c = n.x * n.y * a;
    (
        Vec3::new(1.0 + s * n.x * n.x * a, s * c, -s * n.x),
        Vec3::new(c, s + n.y * n.y * a, -n.y),
    )
}

/// A cosine-distributed direction about `n` from (u1, u2) in [0, 1)^2.
pub fn sample_cosine(n: Vec3, u1: f32, u2: f32) -> Vec3 {
    let r = u1.sqrt();
    let phi = 2.0 * PI * u2;
    let (t, b) = basis_around(n);
    (r * phi.cos() * t + r * phi.sin() * b + (1.0 - u1).max(0.0).sqrt() * n).normalize()
}

/// A uniform direction on the sphere from (u1, u2) in [0, 1)^2.
pub fn sample_sphere(u1: f32, u2: f32) -> Vec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Splits N samples into an nx x ny grid of strata, nx the largest divisor <= sqrt(N).
pub fn strata(n: u32) -> (u32, u32) {
    let mut nx = (n as f64).sqrt().floor() as u32;
    while nx > 1 && !n.is_multiple_of(nx) {
        nx -= 1;
    }
    let nx = nx.max(1);
    (nx, n / nx)
}

#[cfg(test)]
mod tests {
    #[test]
    fn strata_cover_every_sample_count() {
        assert_eq!(super::strata(32), (4, 8));
        assert_eq!(super::strata(4), (2, 2));
        assert_eq!(super::strata(1), (1, 1));
        assert_eq!(super::strata(7), (1, 7));
        for n in 1..=1024 {
            let (a, b) = super::strata(n);
            assert_eq!(a * b, n);
        }
    }
}
