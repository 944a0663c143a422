//! Image error metrics, for `compare`, the accuracy benchmark and tests: RMSE
//! (linear), relative MSE, and SSIM (Wang et al. 2004) on display luminance,
//! all optionally restricted by a mask.

use crate::error::{Error, Result};
use crate::image::{linear_to_srgb, Image};

#[derive(Clone, Debug, serde::Serialize, PartialEq)]
pub struct Metrics {
    /// Root mean square difference of linear RGB over the pixels compared.
    pub rmse: f64,
    /// Mean over pixel channels of (a - b)^2 / (b^2 + 0.01): error relative to
    /// the reference `b`, stable where it is dark (Rousselle et al.'s form).
    pub rel_mse: f64,
    /// Mean structural similarity of sRGB luminance (11 x 11 Gaussian window,
    /// sigma 1.5, K1 = 0.01, K2 = 0.03): 1 is identical.
    pub ssim: f64,
    /// RMSE over the mean of the reference (both over the pixels compared):
    /// the relative error that independent ground truth is quoted in.
    pub rel_rmse: f64,
    /// Mean of `a` over the mean of the reference, same pixels: 1 conserves energy.
    pub energy: f64,
    pub pixels_compared: usize,
}

/// Sums over the kept pixels' channels.
#[derive(Default)]
struct Sums {
    /// (a - b)^2
    se: f64,
    /// (a - b)^2 / (b^2 + 0.01)
    rel: f64,
    a: f64,
    b: f64,
    pixels: usize,
}

fn squared_errors(a: &Image, b: &Image, keep: impl Fn(usize) -> bool) -> Sums {
    let mut s = Sums::default();
    for (i, (p, q)) in a.pixels.iter().zip(&b.pixels).enumerate() {
        if !keep(i) {
            continue;
        }
        for c in 0..3 {
            let d = p[c] as f64 - q[c] as f64;
            s.se += d * d;
            s.rel += d * d / (q[c] as f64 * q[c] as f64 + 0.01);
            s.a += p[c] as f64;
            s.b += q[c] as f64;
        }
        s.pixels += 1;
    }
    s
}

fn same_size(a: &Image, b: &Image) -> Result<()> {
    if (a.width, a.height) != (b.width, b.height) {
        return Err(Error::SizeMismatch {
            a_width: a.width,
            a_height: a.height,
            b_width: b.width,
            b_height: b.height,
        });
    }
    Ok(())
}

/// RMSE of linear RGB alone (no SSIM): for tests and noise figures.
pub fn rmse(a: &Image, b: &Image) -> Result<f64> {
    same_size(a, b)?;
    let s = squared_errors(a, b, |_| true);
    Ok((s.se / (s.pixels.max(1) * 3) as f64).sqrt())
}

/// Compares `a` with the reference `b`; `mask` (same size) keeps pixels where it is true.
pub fn compare(a: &Image, b: &Image, mask: Option<&[bool]>) -> Result<Metrics> {
    same_size(a, b)?;
    if let Some(m) = mask {
        if m.len() != a.pixels.len() {
            return Err(Error::InvalidOption(format!(
                "the mask has {} pixels, the images {}",
                m.len(),
                a.pixels.len()
            )));
        }
    }
    let keep = |i: usize| mask.is_none_or(|m| m[i]);
    let s = squared_errors(a, b, keep);
    let n = s.pixels;
    if n == 0 {
        return Err(Error::InvalidOption("the mask keeps no pixel".into()));
    }
    let ssim_map = ssim_map(a, b);
    let ssim: f64 = ssim_map
        .iter()
        .enumerate()
        .filter(|(i, _)| keep(*i))
        .map(|(_, v)| *v)
        .sum::<f64>()
        / n as f64;
    let rmse = (s.se / (3 * n) as f64).sqrt();
    let mean_b = s.b / (3 * n) as f64;
    Ok(Metrics {
        rmse,
        rel_mse: s.rel / (3 * n) as f64,
        ssim,
        rel_rmse: rmse / mean_b,
        energy: s.a / s.b,
        pixels_compared: n,
    })
}

fn luminance(img: &Image) -> Vec<f64> {
    img.pixels
        .iter()
        .map(|p| {
            0.2126 * linear_to_srgb(p[0]) as f64
                + 0.7152 * linear_to_srgb(p[1]) as f64
                + 0.0722 * linear_to_srgb(p[2]) as f64
        })
        .collect()
}

/// Per-pixel SSIM of display luminance, Gaussian windows clipped at the borders.
pub fn ssim_map(a: &Image, b: &Image) -> Vec<f64> {
    let (w, h) = (a.width as i64, a.height as i64);
    let (la, lb) = (luminance(a), luminance(b));
    let weights: Vec<f64> = (-5..=5)
        .map(|d: i64| (-((d * d) as f64) / (2.0 * 1.5 * 1.5)).exp())
        .collect();
    let (c1, c2) = (0.01f64.powi(2), 0.03f64.powi(2));
    let mut out = vec![0f64; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let (mut sw, mut ma, mut mb, mut vaa, mut vbb, mut vab) =
                (0f64, 0f64, 0f64, 0f64, 0f64, 0f64);
            for dy in -5..=5i64 {
                for dx in -5..=5i64 {
                    let (xx, yy) = (x + dx, y + dy);
                    if xx < 0 || yy < 0 || xx >= w || yy >= h {
                        continue;
                    }
                    let wt = weights[(dx + 5) as usize] * weights[(dy + 5) as usize];
                    let i = (yy * w + xx) as usize;
                    sw += wt;
                    ma += wt * la[i];
                    mb += wt * lb[i];
                    vaa += wt * la[i] * la[i];
                    vbb += wt * lb[i] * lb[i];
                    vab += wt * la[i] * lb[i];
                }
            }
            let (ma, mb) = (ma / sw, mb / sw);
            let (va, vb, cov) = (vaa / sw - ma * ma, vbb / sw - mb * mb, vab / sw - ma * mb);
            out[(y * w + x) as usize] = ((2.0 * ma * mb + c1) * (2.0 * cov + c2))
                / ((ma * ma + mb * mb + c1) * (va + vb + c2));
        }
    }
    out
}

/// A false-colour picture of |a - b| / (|b| + 0.01) (luminance-weighted):
/// black 0, through blue, green and yellow, to red at 1 or more.
pub fn false_colour(a: &Image, b: &Image) -> Image {
    let ramp = [
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [1.0, 0.0, 0.0],
    ];
    let pixels = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| {
            let la = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            let lb = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
            let e = ((la - lb).abs() / (lb.abs() + 0.01)).clamp(0.0, 1.0) * 4.0;
            let i = (e.floor() as usize).min(3);
            let t = e - i as f32;
            let c: [f32; 3] = std::array::from_fn(|k| ramp[i][k] * (1.0 - t) + ramp[i + 1][k] * t);
            // png_bytes applies sRGB; store linear values that encode to the ramp.
            c.map(|v: f32| {
                if v <= 0.04045 {
                    v / 12.92
                } else {
                    ((v + 0.055) / 1.055).powf(2.4)
                }
            })
        })
        .collect();
    Image {
        width: a.width,
        height: a.height,
        pixels,
    }
}

/// NVIDIA's LDR-FLIP (Andersson et al. 2020, through the nv-flip crate, as
/// wgpu's tests use it) of two images' sRGB 8-bit encodings at FLIP's
/// default 67 pixels per degree: the per-pixel error map (0 identical .. 1
/// the most different) and the figures pooled from it.
pub struct FlipMap {
    map: nv_flip::FlipImageFloat,
    /// The map's mean.
    pub mean: f64,
}

/// The FLIP percentiles `compare` and `regress` report, in percent.
pub const FLIP_PERCENTILES: [f64; 4] = [50.0, 90.0, 95.0, 99.0];

/// FLIP's error map of `a` against the reference `b`.
pub fn flip_map(a: &Image, b: &Image) -> Result<FlipMap> {
    same_size(a, b)?;
    let srgb = |img: &Image| -> Vec<u8> {
        img.pixels
            .iter()
            .flat_map(|p| p.map(|c| (linear_to_srgb(c) * 255.0 + 0.5) as u8))
            .collect()
    };
    let (ta, tb) = (srgb(a), srgb(b));
    let test = nv_flip::FlipImageRgb8::with_data(a.width, a.height, &ta);
    let reference = nv_flip::FlipImageRgb8::with_data(b.width, b.height, &tb);
    let map = nv_flip::flip(reference, test, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mean = nv_flip::FlipPool::from_image(&map).mean() as f64;
    Ok(FlipMap { map, mean })
}

impl FlipMap {
    /// FLIP's weighted percentile (`percent` in 0..=100), the one wgpu's
    /// tests gate on: the smallest error e such that the pixels with errors
    /// up to e, in ascending order, hold more than `percent`% of the map's
    /// summed error (0 where the map is all 0).
    pub fn percentile(&self, percent: f64) -> f64 {
        let mut pool = nv_flip::FlipPool::from_image(&self.map);
        pool.get_percentile((percent / 100.0) as f32, true) as f64
    }

    /// The per-pixel errors, row 0 at the top.
    pub fn values(&self) -> Vec<f32> {
        self.map.to_vec()
    }

    /// The map through FLIP's magma colour map (black 0 .. pale yellow 1), as
    /// FLIP's own tool shows it: 8-bit sRGB, three bytes a pixel.
    pub fn magma_srgb8(&self) -> Vec<u8> {
        self.map.apply_color_lut(&nv_flip::magma_lut()).to_vec()
    }

    /// [`FlipMap::magma_srgb8`] as a PNG.
    pub fn magma_png(&self) -> Result<Vec<u8>> {
        crate::image::srgb8_png(self.map.width(), self.map.height(), self.magma_srgb8())
    }
}

/// The mean of [`flip_map`].
pub fn flip(a: &Image, b: &Image) -> Result<f64> {
    Ok(flip_map(a, b)?.mean)
}

/// The fraction of pixels with a channel differing by more than `threshold`
/// (OpenImageIO idiff's --fail).
pub fn fraction_beyond(a: &Image, b: &Image, threshold: f32) -> Result<f64> {
    same_size(a, b)?;
    let beyond = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > threshold))
        .count();
    Ok(beyond as f64 / a.pixels.len().max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient(w: u32, h: u32, k: f32) -> Image {
        let mut img = Image::new(w, h);
        for (i, p) in img.pixels.iter_mut().enumerate() {
            let v = ((i as u32 % w) as f32 / w as f32) * k;
            *p = [v, v * 0.5, 0.2];
        }
        img
    }

    #[test]
    fn identical_images_are_perfect_and_differences_show() {
        let a = gradient(40, 30, 1.0);
        let m = compare(&a, &a, None).unwrap();
        assert_eq!((m.rmse, m.rel_mse), (0.0, 0.0));
        assert!((m.ssim - 1.0).abs() < 1e-12);
        let b = gradient(40, 30, 1.2);
        let d = compare(&b, &a, None).unwrap();
        assert!(d.rmse > 0.01 && d.rel_mse > 0.0 && d.ssim < 1.0, "{d:?}");
        // A mask that keeps only the left column sees almost no difference.
        let mask: Vec<bool> = (0..a.pixels.len()).map(|i| i % 40 == 0).collect();
        let left = compare(&b, &a, Some(&mask)).unwrap();
        assert_eq!(left.pixels_compared, 30);
        assert!(left.rmse < d.rmse / 10.0);
        assert!(compare(&a, &gradient(41, 30, 1.0), None).is_err());
    }

    /// The plain computation of FLIP's weighted percentile over the map's
    /// own values: sorted ascending, the first whose running sum passes p of
    /// the total.
    fn weighted_percentile(values: &[f32], percent: f64) -> f64 {
        let mut v: Vec<f64> = values.iter().map(|&x| x as f64).collect();
        v.sort_by(f64::total_cmp);
        let total: f64 = v.iter().sum();
        let mut running = 0.0;
        for x in &v {
            running += x;
            if running > percent / 100.0 * total {
                return *x;
            }
        }
        0.0
    }

    #[test]
    fn flip_percentiles_match_a_plain_computation() {
        let a = gradient(24, 16, 1.0);
        let mut b = gradient(24, 16, 1.0);
        // A few bright defects over a mild global change: a long tail.
        for (i, p) in b.pixels.iter_mut().enumerate() {
            p[0] *= 1.05;
            if i % 37 == 0 {
                *p = [1.0, 1.0, 1.0];
            }
        }
        let f = flip_map(&b, &a).unwrap();
        let values = f.values();
        assert_eq!(values.len(), 24 * 16);
        let mean = values.iter().map(|&x| x as f64).sum::<f64>() / values.len() as f64;
        assert!((f.mean - mean).abs() < 1e-6, "{} against {mean}", f.mean);
        let mut last = 0.0;
        for p in FLIP_PERCENTILES {
            let (got, plain) = (f.percentile(p), weighted_percentile(&values, p));
            assert!((got - plain).abs() < 1e-6, "p{p}: {got} against {plain}");
            assert!(got >= last, "p{p} {got} below {last}");
            last = got;
        }
        assert!(f.percentile(99.0) > f.percentile(50.0) && f.percentile(50.0) > 0.0);
        // Identical images: an all-zero map, every figure 0, a black picture.
        let same = flip_map(&a, &a).unwrap();
        assert_eq!((same.mean, same.percentile(99.0)), (0.0, 0.0));
        let magma = same.magma_srgb8();
        assert_eq!(magma.len(), 24 * 16 * 3);
        assert!(magma.iter().all(|&c| c < 8), "magma at 0 is near black");
        assert!(f.magma_srgb8().iter().any(|&c| c > 128));
    }
}
