//! Each lobe of the BSDF layer against what a BSDF must be: reciprocal,
//! energy at most 1 (a white furnace), its samples distributed as its pdf
//! says (a chi-square test over the sphere, as pbrt's `bsdfs_test` and
//! Mitsuba's `chi2` do), and each sample's weight equal to f cos / pdf.

use super::*;

/// xorshift64*: a test's own random numbers in [0, 1).
struct Rng(u64);
impl Rng {
    fn f32(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32) / (1u32 << 24) as f32
    }
    fn u(&mut self) -> Vec2 {
        Vec2::new(self.f32(), self.f32())
    }
    /// A direction in the upper hemisphere, uniform in solid angle.
    fn upper(&mut self) -> Vec3 {
        let z = self.f32().max(1e-3);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * self.f32();
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    }
}

const GOLD_ETA: Vec3 = Vec3::new(0.143, 0.374, 1.442);
const GOLD_K: Vec3 = Vec3::new(3.983, 2.385, 1.603);

/// The lobes under test: diffuse, and conductors from nearly smooth to very
/// rough, isotropic and anisotropic, a gold one and a nearly perfect one.
fn lobes() -> Vec<(&'static str, Bsdf)> {
    let perfect = |a: Vec2| Bsdf::conductor(Vec3::ONE, Vec3::splat(0.2), Vec3::splat(10.0), a);
    vec![
        ("diffuse", Bsdf::diffuse(Vec3::new(0.8, 0.5, 0.2))),
        (
            "gold 0.1",
            Bsdf::conductor(Vec3::ONE, GOLD_ETA, GOLD_K, Vec2::splat(0.1)),
        ),
        (
            "gold 0.3",
            Bsdf::conductor(Vec3::ONE, GOLD_ETA, GOLD_K, Vec2::splat(0.3)),
        ),
        ("perfect 0.6", perfect(Vec2::splat(0.6))),
        ("perfect 0.1 x 0.5", perfect(Vec2::new(0.1, 0.5))),
        ("perfect 1.0", perfect(Vec2::splat(1.0))),
        (
            "gold 0.3, separable",
            Bsdf::conductor(Vec3::ONE, GOLD_ETA, GOLD_K, Vec2::splat(0.3))
                .with_model(MICROFACET_SEPARABLE),
        ),
        (
            "beckmann 0.15",
            perfect(Vec2::splat(0.15)).with_model(MICROFACET_BECKMANN | MICROFACET_SEPARABLE),
        ),
        (
            "beckmann 0.5",
            perfect(Vec2::splat(0.5)).with_model(MICROFACET_BECKMANN | MICROFACET_SEPARABLE),
        ),
        (
            "beckmann 0.1 x 0.4",
            perfect(Vec2::new(0.1, 0.4)).with_model(MICROFACET_BECKMANN),
        ),
    ]
}

/// Incoming directions from normal to grazing.
fn wos() -> Vec<Vec3> {
    [0.99f32, 0.7, 0.3, 0.08]
        .iter()
        .enumerate()
        .map(|(i, &z)| {
            let r = (1.0 - z * z).sqrt();
            let phi = 0.7 + 1.3 * i as f32;
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        })
        .collect()
}

#[test]
fn each_lobe_is_reciprocal() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for (name, b) in lobes() {
        for _ in 0..2000 {
            let (wo, wi) = (rng.upper(), rng.upper());
            let (a, c) = (eval_local(&b, wo, wi), eval_local(&b, wi, wo));
            let scale = a.max_element().max(c.max_element()).max(1e-6);
            assert!(
                (a - c).abs().max_element() <= 1e-4 * scale,
                "{name}: f({wo}, {wi}) = {a} but f({wi}, {wo}) = {c}"
            );
        }
    }
}

/// The albedo of each lobe at each wo by importance sampling, with its
/// standard error: at most 1 (white furnace), and for the wide lobes the
/// same as f cos integrated over the hemisphere by quadrature, which does
/// not use the sampler. The diffuse lobe gives its albedo exactly; a nearly
/// perfect conductor loses what single scattering in the microfacet model
/// loses (Trowbridge-Reitz's long tail sends a quarter of the normals seen
/// at normal incidence past 45 degrees at alpha 0.6).
#[test]
fn no_lobe_reflects_more_than_it_receives() {
    let mut rng = Rng(7);
    let n = 200_000;
    for (name, b) in lobes() {
        for wo in wos() {
            let (mut sum, mut sum2) = (0.0f64, 0.0f64);
            for _ in 0..n {
                let s = sample_local(&b, wo, rng.u());
                let w = f64::from(s.weight.max_element());
                sum += w;
                sum2 += w * w;
            }
            let mean = sum / f64::from(n);
            let err = ((sum2 / f64::from(n) - mean * mean).max(0.0) / f64::from(n)).sqrt();
            assert!(
                mean <= 1.0 + 4.0 * err + 1e-4,
                "{name} at {wo}: albedo {mean} ± {err}"
            );
            if name == "diffuse" {
                assert!((mean - 0.8).abs() < 1e-5, "diffuse albedo {mean}");
            }
            if b.alpha.min_element() >= 0.3 {
                let quadrature: f64 =
                    integrate_bins(|wi| f64::from(eval_local(&b, wo, wi).max_element() * wi.z))
                        .iter()
                        .sum();
                assert!(
                    (mean - quadrature).abs() < 4.0 * err + 2e-3,
                    "{name} at {wo}: albedo {mean} ± {err} by sampling, {quadrature} by quadrature"
                );
            }
        }
    }
}

fn sample_local(b: &Bsdf, wo: Vec3, u: Vec2) -> BsdfSample {
    sample(
        b,
        &Frame {
            t: Vec3::X,
            b: Vec3::Y,
            n: Vec3::Z,
        },
        wo,
        u,
    )
}

#[test]
fn each_sample_carries_its_own_pdf_and_weight() {
    let mut rng = Rng(11);
    for (name, b) in lobes() {
        for wo in wos() {
            for _ in 0..2000 {
                let s = sample_local(&b, wo, rng.u());
                if s.lobe == 0 {
                    continue;
                }
                let p = pdf_local(&b, wo, s.wi);
                assert!(
                    (p - s.pdf).abs() <= 2e-3 * p,
                    "{name}: pdf {} against {p}",
                    s.pdf
                );
                let w = eval_local(&b, wo, s.wi) * s.wi.z / p;
                let scale = w.max_element().max(1e-3);
                assert!(
                    (w - s.weight).abs().max_element() <= 2e-3 * scale,
                    "{name}: weight {} against f cos / pdf {w}",
                    s.weight
                );
            }
        }
    }
}

/// Bins over the sphere in (cos theta, phi): `THETA` x `PHI`, equal in
/// solid angle.
const THETA: usize = 10;
const PHI: usize = 20;

fn bin_of(w: Vec3) -> Option<usize> {
    if w.z <= 0.0 {
        return None;
    }
    let t = ((w.z * THETA as f32) as usize).min(THETA - 1);
    let phi = w.y.atan2(w.x).rem_euclid(2.0 * PI);
    let p = ((phi / (2.0 * PI) * PHI as f32) as usize).min(PHI - 1);
    Some(t * PHI + p)
}

/// Each bin's probability: the pdf integrated over the bin, by a midpoint
/// rule of `SUB_Z` x `SUB_PHI` cells a bin in (cos theta, phi), where
/// d omega = d cos theta d phi (fine in cos theta, where a narrow lobe is).
fn expected(b: &Bsdf, wo: Vec3) -> Vec<f64> {
    integrate_bins(|wi| f64::from(pdf_local(b, wo, wi)))
}

fn integrate_bins(g: impl Fn(Vec3) -> f64) -> Vec<f64> {
    const SUB_Z: usize = 160;
    const SUB_PHI: usize = 32;
    let mut p = vec![0.0f64; THETA * PHI];
    let dz = 1.0 / (THETA * SUB_Z) as f64;
    let dphi = 2.0 * std::f64::consts::PI / (PHI * SUB_PHI) as f64;
    for i in 0..THETA * SUB_Z {
        let z = (i as f64 + 0.5) * dz;
        let r = (1.0 - z * z).max(0.0).sqrt();
        for j in 0..PHI * SUB_PHI {
            let phi = (j as f64 + 0.5) * dphi;
            let wi = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            p[(i / SUB_Z) * PHI + j / SUB_PHI] += g(wi) * dz * dphi;
        }
    }
    p
}

/// Pearson's chi-square over the bins, bins expecting fewer than 5 samples
/// pooled (with the samples that failed, which the pdf's deficit predicts),
/// as a Wilson-Hilferty z score: about normal under the hypothesis that the
/// samples follow the pdf.
fn chi_square_z(b: &Bsdf, wo: Vec3, rng: &mut Rng, n: usize) -> f64 {
    let probability = expected(b, wo);
    let mut observed = vec![0.0f64; THETA * PHI];
    let mut failed = 0.0;
    for _ in 0..n {
        let s = sample_local(b, wo, rng.u());
        match (s.lobe != 0).then(|| bin_of(s.wi)).flatten() {
            Some(i) => observed[i] += 1.0,
            None => failed += 1.0,
        }
    }
    let nf = n as f64;
    let total: f64 = probability.iter().sum();
    let (mut chi2, mut dof) = (0.0, 0usize);
    let (mut pooled_o, mut pooled_e) = (failed, (1.0 - total).max(0.0) * nf);
    for (o, p) in observed.iter().zip(&probability) {
        let e = p * nf;
        if e < 5.0 {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            dof += 1;
        }
    }
    if pooled_e >= 5.0 {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        dof += 1;
    } else {
        assert!(
            pooled_o <= 20.0,
            "{pooled_o} samples where the pdf expects {pooled_e}"
        );
    }
    let k = (dof - 1) as f64;
    let h = 2.0 / (9.0 * k);
    ((chi2 / k).cbrt() - (1.0 - h)) / h.sqrt()
}

/// z below 4.5 in every case: about a 3e-6 chance each of failing a correct
/// sampler, while a pdf off by a few percent in some bins fails it.
#[test]
fn samples_follow_the_pdf() {
    let mut rng = Rng(0x5eed);
    for (name, b) in lobes() {
        for wo in wos() {
            let z = chi_square_z(&b, wo, &mut rng, 200_000);
            assert!(z < 4.5, "{name} at {wo}: chi-square z = {z}");
        }
    }
}

/// The test can fail: a sampler of the wrong roughness is caught.
#[test]
fn the_chi_square_test_catches_a_wrong_pdf() {
    let mut rng = Rng(3);
    let sampled = Bsdf::conductor(Vec3::ONE, GOLD_ETA, GOLD_K, Vec2::splat(0.33));
    let claimed = Bsdf::conductor(Vec3::ONE, GOLD_ETA, GOLD_K, Vec2::splat(0.3));
    let wo = wos()[1];
    let probability = expected(&claimed, wo);
    let mut observed = vec![0.0f64; THETA * PHI];
    let n = 200_000;
    for _ in 0..n {
        let s = sample_local(&sampled, wo, rng.u());
        if let Some(i) = (s.lobe != 0).then(|| bin_of(s.wi)).flatten() {
            observed[i] += 1.0;
        }
    }
    let chi2: f64 = observed
        .iter()
        .zip(&probability)
        .filter(|(_, p)| **p * n as f64 >= 5.0)
        .map(|(o, p)| (o - p * n as f64).powi(2) / (p * n as f64))
        .sum();
    assert!(
        chi2 > 1000.0,
        "a 10% roughness error gave chi-square {chi2} only"
    );
    assert!(chi_square_z(&claimed, wo, &mut rng, n) < 4.5);
}

/// Fresnel of a conductor: its normal-incidence value from eta and k, and 1
/// at grazing incidence.
#[test]
fn conductor_fresnel_has_its_limits() {
    let f0 = fresnel_conductor(1.0, GOLD_ETA, GOLD_K);
    let e = GOLD_ETA;
    let k = GOLD_K;
    let expect =
        ((e - Vec3::ONE) * (e - Vec3::ONE) + k * k) / ((e + Vec3::ONE) * (e + Vec3::ONE) + k * k);
    assert!(
        (f0 - expect).abs().max_element() < 1e-5,
        "{f0} against {expect}"
    );
    let grazing = fresnel_conductor(1e-4, GOLD_ETA, GOLD_K);
    assert!(
        (grazing - Vec3::ONE).abs().max_element() < 1e-2,
        "{grazing}"
    );
    // A dielectric (k = 0) matches the dielectric formula.
    let (fd, _) = crate::twins::shading::fresnel_dielectric(0.6, 1.0 / 1.5);
    let fc = fresnel_conductor(0.6, Vec3::splat(1.5), Vec3::ZERO);
    assert!((fc.x - fd).abs() < 1e-5, "{fc} against {fd}");
}
