//! Twins of the shading-normal helpers: `shading_normal` of
//! glsl/common/scene.glsl and the mirror and glass directions of
//! glsl/common/specular.glsl, line for line.

use glam::Vec3;

use crate::scene::{Geometry, Shape};

/// The shading normal at p of `shape`, whose unit geometric normal is n:
/// its vertex normals interpolated by p's barycentric weights, on n's side;
/// n without vertex normals, or where the interpolation points the other way.
pub fn shading_normal(shape: &Shape, p: Vec3, n: Vec3) -> Vec3 {
    let (Some([n0, n1, n2]), Geometry::Triangle { v0, v1, v2 }) = (shape.normals, shape.geometry)
    else {
        return n;
    };
    let (e1, e2) = (v1 - v0, v2 - v0);
    let q = p - v0;
    let c = e1.cross(e2);
    let inv = 1.0 / c.dot(c);
    let w1 = q.cross(e2).dot(c) * inv;
    let w2 = e1.cross(q).dot(c) * inv;
    let s = (1.0 - w1 - w2) * n0 + w1 * n1 + w2 * n2;
    let len = s.length();
    if len.is_nan() || len <= 0.0 || s.dot(n) <= 0.0 {
        return n;
    }
    s / len
}

/// The shading normal on the side d arrives from (as the facing geometric
/// normal is: n when d . n < 0, else -n).
pub fn facing_shading_normal(shape: &Shape, p: Vec3, n: Vec3, d: Vec3) -> Vec3 {
    let front = n.dot(d) < 0.0;
    let s = if shape.normals.is_some() {
        shading_normal(shape, p, n)
    } else {
        n
    };
    if front {
        s
    } else {
        -s
    }
}

/// Fresnel reflectance (glsl/common/fresnel.glsl) and the transmitted cosine.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> (f32, f32) {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (rs * rs + rp * rp), cos_t)
}

fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * n.dot(d) * n
}

/// A mirror (ior 0) or glass direction about the unit normal m facing d;
/// glass reflects when u < F.
pub fn specular_about(d: Vec3, m: Vec3, ior: f32, entering: bool, u: f32) -> Vec3 {
    if ior == 0.0 {
        return reflect(d, m);
    }
    let eta = if entering { 1.0 / ior } else { ior };
    let cos_i = -d.dot(m);
    let (f, cos_t) = fresnel_dielectric(cos_i, eta);
    if u < f {
        reflect(d, m)
    } else {
        eta * d + (eta * cos_i - cos_t) * m
    }
}

/// What a radiance-carrying path's throughput takes leaving for `next` at a
/// surface whose geometric normal nf faces the incoming ray: (eta_i /
/// eta_t)^2 where it refracts, else 1 (`radiance_refraction_scale` in
/// common/specular.glsl).
pub fn radiance_refraction_scale(next: Vec3, nf: Vec3, ior: f32, entering: bool) -> f32 {
    if ior == 0.0 || next.dot(nf) >= 0.0 {
        return 1.0;
    }
    let eta = if entering { 1.0 / ior } else { ior };
    eta * eta
}

/// About the shading normal ms unless d comes from behind it or the result
/// leaves on the wrong side of the geometric surface (then about nf); and
/// whether ms was used.
pub fn specular_shaded(
    d: Vec3,
    nf: Vec3,
    ms: Vec3,
    ior: f32,
    entering: bool,
    u: f32,
) -> (Vec3, bool) {
    if d.dot(ms) < 0.0 {
        let next = specular_about(d, ms, ior, entering, u);
        let reflected = next.dot(ms) > 0.0;
        if reflected == (next.dot(nf) > 0.0) {
            return (next, true);
        }
    }
    (specular_about(d, nf, ior, entering, u), false)
}

/// The photon's weight at a diffuse hit with shading normal ms:
/// |w_in . n_s| / |w_in . n_g| (glsl/photon/bounce.glsl).
pub fn diffuse_adjoint(d: Vec3, nf: Vec3, ms: Vec3) -> f32 {
    let cos_g = -nf.dot(d);
    if cos_g > 0.0 {
        (-ms.dot(d)).max(0.0) / cos_g
    } else {
        0.0
    }
}

/// The photon's weight at a specular bounce about ms:
/// |w_in . n_s| |w_out . n_g| / (|w_in . n_g| |w_out . n_s|).
pub fn specular_adjoint(d: Vec3, next: Vec3, nf: Vec3, ms: Vec3) -> f32 {
    let den = -d.dot(nf) * next.dot(ms).abs();
    if den > 0.0 {
        (-d.dot(ms) * next.dot(nf).abs()) / den
    } else {
        0.0
    }
}
