//! Image regression by a per-pixel z-test (Mitsuba's scheme): a reference is
//! the mean of N seeds and the per-pixel variance of one render (plus the
//! squared difference between two llvmpipe SIMD widths, for driver rounding);
//! a render is scored by the fraction of pixel channels whose
//! z = (x - mean) / sqrt(var (1 + 1/N) + floor^2) exceeds 4 in magnitude. The
//! tolerance on that fraction is measured, not chosen: each seed scored against
//! the other seeds' mean and variance (leave-one-out), mean + 4 sigma. These
//! references test repeatability of the one-shot estimator, not truth (SPPM
//! references do that).

use std::path::{Path, PathBuf};

use crate::error::{Error, Result};
use crate::image::{write_all_atomically, Image};

pub const Z_LIMIT: f32 = 4.0;

/// The tolerance file beside a reference.
#[derive(serde::Serialize, serde::Deserialize, Debug, Clone)]
pub struct Tolerance {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub seeds: u32,
    pub renderer: String,
    /// Fraction of pixel channels beyond |z| = 4, each seed against the others.
    pub loo_fail_mean: f64,
    pub loo_fail_std: f64,
    /// RMSE between SIMD widths 128 and default, same seed.
    pub driver_rmse: f64,
    /// The largest failing fraction a render may show.
    pub tolerance: f64,
    pub command: String,
}

/// A reference: mean, variance and tolerance.
pub struct Reference {
    pub mean: Image,
    pub var: Image,
    pub tol: Tolerance,
}

/// The three files of reference `name` in `dir`: mean, variance, tolerance.
pub fn paths(dir: &Path, name: &str) -> (PathBuf, PathBuf, PathBuf) {
    (
        dir.join(format!("{name}.exr")),
        dir.join(format!("{name}.var.exr")),
        dir.join(format!("{name}.json")),
    )
}

impl Reference {
    pub fn load(dir: &Path, name: &str) -> Result<Self> {
        let (exr, var, json) = paths(dir, name);
        let text = std::fs::read_to_string(&json).map_err(|e| Error::io("read", &json, e))?;
        let tol: Tolerance = serde_json::from_str(&text).map_err(|e| {
            Error::InvalidOption(format!(
                "{}: not a regression tolerance: {e}",
                json.display()
            ))
        })?;
        Ok(Self {
            mean: Image::read_exr(&exr)?,
            var: Image::read_exr(&var)?,
            tol,
        })
    }

    pub fn write(&self, dir: &Path, name: &str) -> Result<()> {
        let (exr, var, json) = paths(dir, name);
        let (a, b) = (self.mean.exr_bytes()?, self.var.exr_bytes()?);
        let c = serde_json::to_string_pretty(&self.tol).unwrap_or_default() + "\n";
        write_all_atomically(&[(&exr, &a), (&var, &b), (&json, c.as_bytes())])
    }

    /// The fraction of `actual`'s channels beyond |z| = 4.
    pub fn failing_fraction(&self, actual: &Image) -> f64 {
        failing_fraction(actual, &self.mean, &self.var, self.tol.seeds)
    }

    /// |z| / 4 per channel as an image: 1 and above fail.
    pub fn z_map(&self, actual: &Image) -> Image {
        let mut out = actual.clone();
        let n = self.tol.seeds;
        for ((o, m), v) in out
            .pixels
            .iter_mut()
            .zip(&self.mean.pixels)
            .zip(&self.var.pixels)
        {
            for c in 0..3 {
                o[c] = ((o[c] - m[c]) / sd(m[c], v[c], n)).abs() / Z_LIMIT;
            }
        }
        out
    }
}

/// The standard deviation a channel is allowed: the variance of one render
/// against a mean of n, and a rounding floor of 1e-3 of the mean (+ 1e-6) for
/// pixels no seed changes (a point light's shadow edge).
fn sd(mean: f32, var: f32, n: u32) -> f32 {
    let floor = 1e-3 * mean.abs() + 1e-6;
    (var * (1.0 + 1.0 / n as f32) + floor * floor).sqrt()
}

/// Fraction of pixel channels with |z| > Z_LIMIT against a mean and variance of `n` seeds.
pub fn failing_fraction(actual: &Image, mean: &Image, var: &Image, n: u32) -> f64 {
    let mut failing = 0usize;
    for ((x, m), v) in actual.pixels.iter().zip(&mean.pixels).zip(&var.pixels) {
        for c in 0..3 {
            if ((x[c] - m[c]) / sd(m[c], v[c], n)).abs() > Z_LIMIT {
                failing += 1;
            }
        }
    }
    failing as f64 / (actual.pixels.len() * 3).max(1) as f64
}

/// Per-pixel sample variance of images about their mean.
pub fn variance(images: &[Image], mean: &Image) -> Image {
    let mut var = Image::new(mean.width, mean.height);
    for img in images {
        for ((v, p), m) in var.pixels.iter_mut().zip(&img.pixels).zip(&mean.pixels) {
            for c in 0..3 {
                v[c] += (p[c] - m[c]).powi(2) / (images.len() - 1).max(1) as f32;
            }
        }
    }
    var
}

/// A reference from renders of seeds 1..=N and, for driver rounding, one of
/// them rendered again with another SIMD width (`narrow` of `images[0]`).
pub fn make_reference(images: &[Image], narrow: &Image, mut tol: Tolerance) -> Result<Reference> {
    if images.len() < 3 {
        return Err(Error::InvalidOption(
            "a regression reference needs at least 3 seeds".into(),
        ));
    }
    let driver_var = |var: &mut Image| {
        for ((v, a), b) in var
            .pixels
            .iter_mut()
            .zip(&images[0].pixels)
            .zip(&narrow.pixels)
        {
            for c in 0..3 {
                v[c] += (a[c] - b[c]).powi(2);
            }
        }
    };
    let n = images.len() as u32;
    let loo: Vec<f64> = (0..images.len())
        .map(|i| {
            let others: Vec<Image> = images
                .iter()
                .enumerate()
                .filter(|(j, _)| *j != i)
                .map(|(_, im)| im.clone())
                .collect();
            let m = Image::average(&others);
            let mut v = variance(&others, &m);
            driver_var(&mut v);
            failing_fraction(&images[i], &m, &v, n - 1)
        })
        .collect();
    let m = loo.iter().sum::<f64>() / loo.len() as f64;
    let sd = (loo.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (loo.len() - 1) as f64).sqrt();
    let mean = Image::average(images);
    let mut var = variance(images, &mean);
    driver_var(&mut var);
    tol.seeds = n;
    tol.loo_fail_mean = m;
    tol.loo_fail_std = sd;
    tol.driver_rmse = crate::metrics::rmse(&images[0], narrow)?;
    tol.tolerance = m + 4.0 * sd;
    tol.width = mean.width;
    tol.height = mean.height;
    Ok(Reference { mean, var, tol })
}
