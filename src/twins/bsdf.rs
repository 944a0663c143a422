//! Twin of glsl/common/bsdf.glsl, line for line: the BSDF layer's evaluate,
//! pdf and sample (diffuse, and the microfacet conductor: Trowbridge-Reitz
//! or Beckmann, height-correlated or separable masking), and the
//! delta lobes' factor. Its tests hold each lobe to what a BSDF must be:
//! reciprocal, at most energy 1 (a white furnace), and sampled as its pdf
//! says (a chi-square test, as pbrt's and Mitsuba's BSDF tests do).

use glam::{Vec2, Vec3};

use crate::layout::{
    BSDF_DELTA, BSDF_DIFFUSE, BSDF_GLOSSY, MAT_CONDUCTOR, MAT_DIFFUSE, MAT_EMITTER,
    MICROFACET_BECKMANN, MICROFACET_SEPARABLE,
};
use crate::sampling::{basis_around, sample_cosine};
use crate::scene::Material;

const PI: f32 = std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    pub kind: u32,
    pub color: Vec3,
    pub ior: f32,
    pub alpha: Vec2,
    pub eta: Vec3,
    pub k: Vec3,
    pub model: u32,
}

impl Bsdf {
    pub fn diffuse(albedo: Vec3) -> Self {
        Self {
            kind: MAT_DIFFUSE,
            color: albedo,
            ior: 1.0,
            alpha: Vec2::ZERO,
            eta: Vec3::ONE,
            k: Vec3::ZERO,
            model: 0,
        }
    }

    pub fn conductor(tint: Vec3, eta: Vec3, k: Vec3, alpha: Vec2) -> Self {
        Self {
            kind: MAT_CONDUCTOR,
            color: tint,
            ior: 1.0,
            alpha,
            eta,
            k,
            model: 0,
        }
    }

    /// The same lobe with the microfacet model `model` (MICROFACET_* bits).
    pub fn with_model(self, model: u32) -> Self {
        Self { model, ..self }
    }

    pub fn lobes(&self) -> u32 {
        if self.kind == MAT_DIFFUSE {
            return BSDF_DIFFUSE;
        }
        if self.kind == MAT_CONDUCTOR && self.alpha.x * self.alpha.y > 0.0 {
            return BSDF_GLOSSY;
        }
        if self.kind == MAT_EMITTER {
            return 0;
        }
        BSDF_DELTA
    }
}

/// A rough metal's lobe (`material_bsdf` of a rough conductor); None for
/// any other material.
pub fn rough_metal(m: &Material) -> Option<Bsdf> {
    match *m {
        Material::Conductor {
            eta,
            k,
            tint,
            alpha,
            microfacet,
        } if alpha > 0.0 => {
            Some(Bsdf::conductor(tint, eta, k, Vec2::splat(alpha)).with_model(microfacet.bits()))
        }
        _ => None,
    }
}

/// What a smooth metal's delta lobe multiplies a path by, leaving about the
/// unit normal m that d meets (`bsdf_delta_direction`): its tint times its
/// Fresnel; 1 for every other material.
pub fn smooth_metal_factor(material: &Material, d: Vec3, m: Vec3) -> Vec3 {
    match *material {
        Material::Conductor { eta, k, tint, .. } => {
            tint * fresnel_conductor((-d.dot(m)).min(1.0), eta, k)
        }
        _ => Vec3::ONE,
    }
}

/// A shading frame: n the normal on wo's side, t and b tangents.
#[derive(Clone, Copy, Debug)]
pub struct Frame {
    pub t: Vec3,
    pub b: Vec3,
    pub n: Vec3,
}

impl Frame {
    pub fn around(n: Vec3) -> Self {
        let (t, b) = basis_around(n);
        Self { t, b, n }
    }
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.t), v.dot(self.b), v.dot(self.n))
    }
    pub fn from_local(&self, v: Vec3) -> Vec3 {
        v.x * self.t + v.y * self.b + v.z * self.n
    }
}

/// Unpolarised Fresnel reflectance of a conductor of index eta + i k.
pub fn fresnel_conductor(c: f32, eta: Vec3, k: Vec3) -> Vec3 {
    let cos2 = c * c;
    let sin2 = 1.0 - cos2;
    let eta2 = eta * eta;
    let k2 = k * k;
    let t0 = eta2 - k2 - Vec3::splat(sin2);
    let a2b2 = (t0 * t0 + 4.0 * eta2 * k2).sqrt();
    let t1 = a2b2 + Vec3::splat(cos2);
    let a = (0.5 * (a2b2 + t0)).max(Vec3::ZERO).sqrt();
    let t2 = 2.0 * c * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2b2 + Vec3::splat(sin2 * sin2);
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rp + rs)
}

pub fn ggx_d(alpha: Vec2, m: Vec3) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let e = (m.x * m.x) / (alpha.x * alpha.x) + (m.y * m.y) / (alpha.y * alpha.y) + m.z * m.z;
    1.0 / (PI * alpha.x * alpha.y * e * e)
}

pub fn ggx_lambda(alpha: Vec2, w: Vec3) -> f32 {
    let z2 = w.z * w.z;
    if z2 == 0.0 {
        return 1e30;
    }
    let a2t2 = (w.x * w.x * alpha.x * alpha.x + w.y * w.y * alpha.y * alpha.y) / z2;
    0.5 * ((1.0 + a2t2).sqrt() - 1.0)
}

pub fn ggx_g1(alpha: Vec2, w: Vec3) -> f32 {
    1.0 / (1.0 + ggx_lambda(alpha, w))
}

pub fn ggx_sample_visible(alpha: Vec2, wo: Vec3, u: Vec2) -> Vec3 {
    let mut wh = Vec3::new(alpha.x * wo.x, alpha.y * wo.y, wo.z).normalize();
    if wh.z < 0.0 {
        wh = -wh;
    }
    let t1 = if wh.z < 0.99999 {
        Vec3::Z.cross(wh).normalize()
    } else {
        Vec3::X
    };
    let t2 = wh.cross(t1);
    let r = u.x.sqrt();
    let phi = 2.0 * PI * u.y;
    let mut p = Vec2::new(r * phi.cos(), r * phi.sin());
    let h = (1.0 - p.x * p.x).max(0.0).sqrt();
    let s = 0.5 * (1.0 + wh.z);
    p.y = h * (1.0 - s) + p.y * s;
    let pz = (1.0 - p.dot(p)).max(0.0).sqrt();
    let nh = p.x * t1 + p.y * t2 + pz * wh;
    Vec3::new(alpha.x * nh.x, alpha.y * nh.y, nh.z.max(1e-6)).normalize()
}

pub fn ggx_pdf_visible(alpha: Vec2, wo: Vec3, m: Vec3) -> f32 {
    ggx_g1(alpha, wo) / wo.z.abs() * ggx_d(alpha, m) * wo.dot(m).abs()
}

pub fn beckmann_d(alpha: Vec2, m: Vec3) -> f32 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let z2 = m.z * m.z;
    let e = ((m.x * m.x) / (alpha.x * alpha.x) + (m.y * m.y) / (alpha.y * alpha.y)) / z2;
    (-e).exp() / (PI * alpha.x * alpha.y * z2 * z2)
}

pub fn beckmann_lambda(alpha: Vec2, w: Vec3) -> f32 {
    let r = (w.x * w.x * alpha.x * alpha.x + w.y * w.y * alpha.y * alpha.y).sqrt();
    if r == 0.0 {
        return 0.0;
    }
    let a = w.z.abs() / r;
    if a >= 1.6 {
        return 0.0;
    }
    if a == 0.0 {
        return 1e30;
    }
    let g1 = (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a);
    1.0 / g1 - 1.0
}

pub fn beckmann_sample(alpha: Vec2, u: Vec2) -> Vec3 {
    let mut phi = 2.0 * PI * u.y;
    if alpha.x != alpha.y {
        phi = (alpha.y * phi.sin()).atan2(alpha.x * phi.cos());
    }
    let (c, s) = (phi.cos(), phi.sin());
    let tan2 =
        -(1.0 - u.x).max(1e-30).ln() / (c * c / (alpha.x * alpha.x) + s * s / (alpha.y * alpha.y));
    let cos_t = 1.0 / (1.0 + tan2).sqrt();
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    Vec3::new(sin_t * c, sin_t * s, cos_t)
}

fn is_beckmann(b: &Bsdf) -> bool {
    b.model & MICROFACET_BECKMANN != 0
}

pub fn mf_d(b: &Bsdf, m: Vec3) -> f32 {
    if is_beckmann(b) {
        beckmann_d(b.alpha, m)
    } else {
        ggx_d(b.alpha, m)
    }
}

pub fn mf_lambda(b: &Bsdf, w: Vec3) -> f32 {
    if is_beckmann(b) {
        beckmann_lambda(b.alpha, w)
    } else {
        ggx_lambda(b.alpha, w)
    }
}

pub fn mf_g(b: &Bsdf, wo: Vec3, wi: Vec3) -> f32 {
    let (lo, li) = (mf_lambda(b, wo), mf_lambda(b, wi));
    if b.model & MICROFACET_SEPARABLE != 0 {
        return 1.0 / ((1.0 + lo) * (1.0 + li));
    }
    1.0 / (1.0 + lo + li)
}

pub fn mf_pdf_m(b: &Bsdf, wo: Vec3, m: Vec3) -> f32 {
    if is_beckmann(b) {
        return beckmann_d(b.alpha, m) * m.z;
    }
    ggx_pdf_visible(b.alpha, wo, m)
}

/// f(wo, wi) of the non-delta lobes, local directions.
pub fn eval_local(b: &Bsdf, wo: Vec3, wi: Vec3) -> Vec3 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return Vec3::ZERO;
    }
    if b.kind == MAT_DIFFUSE {
        return b.color / PI;
    }
    if b.lobes() != BSDF_GLOSSY {
        return Vec3::ZERO;
    }
    let m = wo + wi;
    if m.dot(m) == 0.0 {
        return Vec3::ZERO;
    }
    let m = m.normalize();
    let f = fresnel_conductor(wo.dot(m).abs(), b.eta, b.k);
    b.color * f * (mf_d(b, m) * mf_g(b, wo, wi) / (4.0 * wo.z * wi.z))
}

pub fn pdf_local(b: &Bsdf, wo: Vec3, wi: Vec3) -> f32 {
    if wo.z <= 0.0 || wi.z <= 0.0 {
        return 0.0;
    }
    if b.kind == MAT_DIFFUSE {
        return wi.z / PI;
    }
    if b.lobes() != BSDF_GLOSSY {
        return 0.0;
    }
    let m = wo + wi;
    if m.dot(m) == 0.0 {
        return 0.0;
    }
    let m = m.normalize();
    mf_pdf_m(b, wo, m) / (4.0 * wo.dot(m).abs())
}

pub fn eval(b: &Bsdf, f: &Frame, wo: Vec3, wi: Vec3) -> Vec3 {
    eval_local(b, f.to_local(wo), f.to_local(wi))
}

pub fn pdf(b: &Bsdf, f: &Frame, wo: Vec3, wi: Vec3) -> f32 {
    pdf_local(b, f.to_local(wo), f.to_local(wi))
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    pub wi: Vec3,
    pub weight: Vec3,
    pub pdf: f32,
    pub lobe: u32,
}

fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * n.dot(d) * n
}

pub fn sample(b: &Bsdf, f: &Frame, wo: Vec3, u: Vec2) -> BsdfSample {
    let none = BsdfSample {
        wi: Vec3::ZERO,
        weight: Vec3::ZERO,
        pdf: 0.0,
        lobe: 0,
    };
    if b.kind == MAT_DIFFUSE {
        let wi = sample_cosine(f.n, u.x, u.y);
        return BsdfSample {
            wi,
            pdf: wi.dot(f.n).max(0.0) / PI,
            weight: b.color,
            lobe: BSDF_DIFFUSE,
        };
    }
    if b.lobes() != BSDF_GLOSSY {
        return none;
    }
    let lo = f.to_local(wo);
    if lo.z <= 0.0 {
        return none;
    }
    let m = if is_beckmann(b) {
        beckmann_sample(b.alpha, u)
    } else {
        ggx_sample_visible(b.alpha, lo, u)
    };
    if lo.dot(m) <= 0.0 {
        return none;
    }
    let li = reflect(-lo, m);
    if li.z <= 0.0 {
        return none;
    }
    let pdf = mf_pdf_m(b, lo, m) / (4.0 * lo.dot(m).abs());
    // Not positive, or NaN.
    if pdf.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return none;
    }
    BsdfSample {
        wi: f.from_local(li).normalize(),
        weight: eval_local(b, lo, li) * li.z / pdf,
        pdf,
        lobe: BSDF_GLOSSY,
    }
}

#[cfg(test)]
mod tests;
