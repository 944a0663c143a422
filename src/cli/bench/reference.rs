//! `photonmap reference`: a reference image by stochastic progressive photon
//! mapping, which converges to the exact image, so that accuracy is measured
//! against truth and not against the paper's estimator itself. Two independent
//! halves (their own seeds) are rendered; their mean is the reference, half
//! their RMSE difference its remaining noise, and the change since a quarter of
//! the iterations, extrapolated by SPPM's rate of convergence, estimates and
//! bounds its remaining bias (see [`bias_bound`]).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::{Deserialize, Serialize};

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_atomically;
use photonmap::metrics::rmse;
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::sppm::{Sppm, SppmOptions};
use photonmap::render::{Image, Method, PhotonMapOptions, RenderOptions};
use photonmap::scene::Scene;
use photonmap::timing::Timings;

use super::output::stem;
use crate::cli::args::{in_range, SceneArgs};

/// Render a reference of a scene by SPPM (it converges to the exact image):
/// two independent halves averaged, as EXR, with a JSON of its command, its
/// remaining noise and a bound on its remaining bias.
#[derive(Args)]
pub struct ReferenceArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Output EXR (default: photonmap-out/reference/<scene>.sppm.exr under the
    /// current folder; a .json goes beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Render at 1/scale of the scene's resolution (1..=16).
    #[arg(long, default_value_t = 2, value_parser = in_range(1, 16))]
    pub scale: u32,
    /// SPPM iterations of each half (4..=1000000).
    #[arg(long, default_value_t = 1024, value_parser = in_range(4, 1_000_000))]
    pub iterations: u32,
    /// Photons emitted per iteration (64..=4194304).
    #[arg(long, default_value_t = 16384, value_parser = in_range(64, 1 << 22))]
    pub photons_per_iteration: u32,
    /// Every pixel's first radius (default: the scene's max_radius).
    #[arg(long)]
    pub radius: Option<f32>,
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
pub struct ReferenceInfo {
    pub scene: String,
    pub method: String,
    pub width: u32,
    pub height: u32,
    /// Iterations of each of the two halves.
    pub iterations: u32,
    pub photons_per_iteration: u32,
    pub initial_radius: f32,
    pub alpha: f32,
    /// RMSE of the reference's remaining noise: half the RMSE between the halves.
    pub residual_noise_rmse: f64,
    /// Its remaining bias, estimated and bounded (see [`bias_bound`]). Absent
    /// from references written before it was (their `residual_bias_rmse`, a
    /// change clipped to 0 within the noise, is not read: it was no bound).
    #[serde(flatten, default, skip_serializing_if = "Option::is_none")]
    pub bias: Option<ReferenceBias>,
    pub seconds: f64,
    pub command: String,
    pub renderer: String,
}

pub fn run(a: &ReferenceArgs, platform: Platform) -> Result<()> {
    let scene = a.scene.load()?.scene;
    let out = a.out.clone().unwrap_or_else(|| {
        crate::cli::out_dir("reference").join(format!("{}.sppm.exr", stem(&a.scene.scene)))
    });
    if let Some(dir) = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty() && a.out.is_none())
    {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    crate::cli::check_output(&out, "exr", "--out")?;
    let gpu = crate::cli::gpu(platform)?;
    let mut command = format!(
        "photonmap reference {} --scale {} --iterations {} --photons-per-iteration {}",
        a.scene.scene.display(),
        a.scale,
        a.iterations,
        a.photons_per_iteration
    );
    if let Some(r) = a.radius {
        command += &format!(" --radius {r}");
    }
    for (k, v) in &a.scene.set {
        command += &format!(" --set {k}={v}");
    }
    let progress = crate::cli::progress_lines(a.quiet);
    let (img, info) = make_reference(&gpu, &scene, a, command, &progress)?;
    write_reference(&img, &info, &out)?;
    let bias = info.bias.as_ref().expect("a new reference has its bias");
    eprintln!(
        "wrote {} (remaining noise RMSE {:.5}; bias RMSE estimated {:.5}, at most {:.5} at 95%{})",
        out.display(),
        info.residual_noise_rmse,
        bias.bias_estimate_rmse,
        bias.bias_bound_rmse_95,
        if bias.bias_resolved {
            ""
        } else {
            "; not resolved from the noise, which sets the bound"
        }
    );
    Ok(())
}

/// `scene`'s frame at 1/`scale` of its resolution, at least a pixel a side.
pub fn scaled_size(scene: &Scene, scale: u32) -> (u32, u32) {
    (
        (scene.camera.width / scale).max(1),
        (scene.camera.height / scale).max(1),
    )
}

/// The size and seed every reference half runs with (and the visibility leak
/// test for the paper's estimate; SPPM's own is set in `make_reference`, so
/// that thin walls do not leak while the radius is still large).
pub fn reference_options(scene: &Scene, scale: u32, seed: u32) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height) = scaled_size(scene, scale);
    o.seed = seed;
    let mut map = PhotonMapOptions::default();
    map.estimate.leak = LeakTest::Visibility;
    o.with_method(Method::PhotonMap(map))
}

pub fn make_reference(
    gpu: &Gpu,
    scene: &Scene,
    a: &ReferenceArgs,
    command: String,
    progress: &dyn Fn(&str),
) -> Result<(Image, ReferenceInfo)> {
    let sppm = SppmOptions {
        iterations: a.iterations,
        photons_per_iteration: a.photons_per_iteration,
        initial_radius: a.radius,
        leak: Some(LeakTest::Visibility),
        ..SppmOptions::default()
    };
    let wall = std::time::Instant::now();
    let mut halves = Vec::new();
    let mut quarters = Vec::new();
    let mut initial_radius = 0.0;
    for half in 0..2u32 {
        let options = reference_options(scene, a.scale, 1001 + half);
        let mut run = Sppm::new(gpu, scene, &options, &sppm)?;
        initial_radius = run.initial_radius;
        let mut timings = Timings::default();
        while run.iteration < a.iterations {
            run.iterate(&mut timings, &mut ())?;
            if run.iteration == a.iterations / 4 {
                quarters.push(run.image()?);
            }
            if run.iteration.is_multiple_of(64) {
                progress(&format!(
                    "reference {}: half {} of 2, iteration {} of {}",
                    scene.name,
                    half + 1,
                    run.iteration,
                    a.iterations
                ));
            }
        }
        halves.push(run.image()?);
    }
    let noise = rmse(&halves[0], &halves[1])? / 2.0;
    let bias = bias_bound(
        [&quarters[0], &quarters[1]],
        [&halves[0], &halves[1]],
        sppm.alpha,
    )?;
    let full = Image::average(&halves);
    let info = ReferenceInfo {
        scene: scene.name.clone(),
        method: "sppm".into(),
        width: full.width,
        height: full.height,
        iterations: a.iterations,
        photons_per_iteration: a.photons_per_iteration,
        initial_radius,
        alpha: sppm.alpha,
        residual_noise_rmse: noise,
        bias: Some(bias),
        seconds: wall.elapsed().as_secs_f64(),
        command,
        renderer: gpu.capabilities().gl_renderer,
    };
    Ok((full, info))
}

/// A reference's remaining bias, estimated and bounded by [`bias_bound`].
#[derive(Serialize, Deserialize, Debug, Clone, PartialEq)]
pub struct ReferenceBias {
    /// The RMSE over pixel-channels of the bias left at N iterations, from the
    /// unbiased estimate of its mean square (0 where that is not positive).
    pub bias_estimate_rmse: f64,
    /// A one-sided 95% upper bound on that RMSE (the noise's own size where
    /// the bias is not resolved; never 0 while there is noise).
    pub bias_bound_rmse_95: f64,
    /// Whether the bias is resolved from the noise: the 95% lower bound on its
    /// mean square is above 0. If not, what was seen may be all noise, and
    /// the bound is set by the noise's size.
    pub bias_resolved: bool,
    /// The unbiased estimate of the bias's mean square (may be negative).
    pub bias_mse_estimate: f64,
    /// Its standard error.
    pub bias_mse_stderr: f64,
    /// r / (1 - r), r = 4^-(1 - alpha): the bias left at N over the change
    /// from N/4 to N.
    pub bias_extrapolation: f64,
    /// The model these figures assume.
    pub bias_model: String,
}

/// Side in pixels of the tiles whose means give the standard error: pixels
/// near each other share photons (a pixel's channels share all of theirs), so
/// their noise is correlated and single pixels are not independent samples.
const BIAS_TILE: u32 = 8;
/// The standard normal's one-sided 95% point.
const Z_95: f64 = 1.644_853_626_951_472_2;

/// The bias left in a reference of two independent SPPM halves A and B at N
/// iterations, from their images Q_A, Q_B at N/4 and F_A, F_B at N.
///
/// Model: a pixel's SPPM bias falls as beta(i) = c i^-(1 - alpha) (the radius
/// shrinks so that R^2 ~ i^-(1 - alpha), and the bias of a smooth radiance
/// goes as R^2), with the scheme's alpha, already from N/4 iterations on. Then
/// with r = beta(N) / beta(N/4) = 4^-(1 - alpha), the change
/// b = E[F - Q] = beta(N) (1 - 1/r), so the bias left at N is
///
///   beta(N) = -b r / (1 - r)            (r / (1 - r) = 1.94 at alpha = 0.7).
///
/// The noise: D_A = F_A - Q_A and D_B = F_B - Q_B are independent, each with
/// mean b. (Q is a prefix of the same run as F, so the noise of the two is
/// correlated, and D's noise is not var Q + var F; the halves give it
/// directly.) D = (D_A + D_B) / 2 has E[D^2] = b^2 + var D, and
/// ((D_A - D_B) / 2)^2 has mean var D, so per pixel-channel
///
///   u = D^2 - ((D_A - D_B) / 2)^2 = D_A D_B,   E[u] = b^2.
///
/// U, the mean of u over the M pixel-channels, is unbiased for the mean
/// square of b. Its standard error comes from tiles of 8 x 8 pixels (all
/// channels; single pixels where the image holds fewer than 16 such tiles),
/// T tiles with sums S_t of n_t values:
///
///   SE^2 = T / (T - 1) * sum_t (S_t - n_t U)^2 / M^2.
///
/// With k = r / (1 - r) the bias's mean square at N is estimated by k^2 U, and
///
///   bias_estimate_rmse = k sqrt(max(U, 0)),
///   bias_bound_rmse_95 = k sqrt(max(U, 0) + 1.645 SE)   (one-sided 95%),
///   bias_resolved      = U - 1.645 SE > 0.
///
/// Flooring U at 0 in the bound only widens it, so that it is never below the
/// noise's own size (a negative U is noise too).
pub fn bias_bound(quarters: [&Image; 2], fulls: [&Image; 2], alpha: f32) -> Result<ReferenceBias> {
    let (w, h) = (fulls[0].width, fulls[0].height);
    if quarters
        .iter()
        .chain(&fulls)
        .any(|i| (i.width, i.height) != (w, h) || i.pixels.len() != w as usize * h as usize)
    {
        bail!("the reference's four images are not all {w} x {h}");
    }
    if (w as u64) * (h as u64) < 2 {
        bail!("a {w} x {h} reference is too small to estimate its bias");
    }
    let tile = if (w / BIAS_TILE) * (h / BIAS_TILE) >= 16 {
        BIAS_TILE
    } else {
        1
    };
    let tiles_x = w.div_ceil(tile);
    let mut tiles = vec![(0f64, 0f64); (tiles_x * h.div_ceil(tile)) as usize];
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            let t = &mut tiles[((y / tile) * tiles_x + x / tile) as usize];
            for c in 0..3 {
                let da = fulls[0].pixels[i][c] as f64 - quarters[0].pixels[i][c] as f64;
                let db = fulls[1].pixels[i][c] as f64 - quarters[1].pixels[i][c] as f64;
                t.0 += da * db;
                t.1 += 1.0;
            }
        }
    }
    let m: f64 = tiles.iter().map(|t| t.1).sum();
    let u = tiles.iter().map(|t| t.0).sum::<f64>() / m;
    let count = tiles.len() as f64;
    let spread: f64 = tiles.iter().map(|t| (t.0 - t.1 * u).powi(2)).sum();
    let se = (count / (count - 1.0) * spread).sqrt() / m;
    let r = 4f64.powf(-(1.0 - alpha as f64));
    let k = r / (1.0 - r);
    Ok(ReferenceBias {
        bias_estimate_rmse: k * u.max(0.0).sqrt(),
        bias_bound_rmse_95: k * (u.max(0.0) + Z_95 * se).sqrt(),
        bias_resolved: u - Z_95 * se > 0.0,
        bias_mse_estimate: k * k * u,
        bias_mse_stderr: k * k * se,
        bias_extrapolation: k,
        bias_model: format!(
            "SPPM's bias at iteration i is c i^-(1 - alpha) per pixel, alpha = {alpha} (the \
             scheme's), from N/4 iterations on; so the bias left at N is -D r/(1 - r), \
             r = 4^-(1 - alpha) = {r:.4}, D the mean image at N less the mean at N/4. \
             D's noise is removed using the two independent halves (the mean of D_A D_B is \
             unbiased for D's squared mean); the bound is one-sided 95%, from the standard \
             error over {tile} x {tile}-pixel tiles"
        ),
    })
}

pub fn write_reference(img: &Image, info: &ReferenceInfo, exr: &Path) -> Result<()> {
    write_atomically(exr, &img.exr_bytes()?)?;
    write_atomically(
        &exr.with_extension("json"),
        (serde_json::to_string_pretty(info)? + "\n").as_bytes(),
    )?;
    Ok(())
}

/// A reference and its JSON, as `photonmap reference` writes them.
pub fn read_reference(exr: &Path) -> Result<(Image, ReferenceInfo)> {
    let img = Image::read_exr(exr)?;
    let json = exr.with_extension("json");
    let info: ReferenceInfo = serde_json::from_str(
        &std::fs::read_to_string(&json).with_context(|| format!("reading {}", json.display()))?,
    )
    .with_context(|| format!("{}: not a reference's JSON", json.display()))?;
    Ok((img, info))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Standard normal deviates: splitmix64, then Box-Muller.
    struct Normal(u64);

    impl Normal {
        fn uniform(&mut self) -> f64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn next(&mut self) -> f64 {
            let (a, b) = (1.0 - self.uniform(), self.uniform());
            (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
        }
    }

    const ALPHA: f32 = 0.7;

    /// Two halves, each a quarter image and a full one, of a truth of 0.5 with
    /// `beta` the bias left at N (so beta / r at N/4), and Gaussian noise of
    /// sd 0.05 at N/4 and 0.03 at N, correlated 0.5 within a half as a prefix
    /// of the same run would be. Returns the quarters, the fulls and the true
    /// RMSE of the mean's bias.
    fn synthetic(
        w: u32,
        h: u32,
        beta: impl Fn(u32, u32, usize) -> f64,
        seed: u64,
    ) -> ([Image; 2], [Image; 2], f64) {
        let r = 4f64.powf(-(1.0 - ALPHA as f64));
        let (sq, sf, rho) = (0.05, 0.03, 0.5f64);
        let mut rng = Normal(seed);
        let blank = Image {
            width: w,
            height: h,
            pixels: vec![[0.0; 3]; (w * h) as usize],
        };
        let (mut q, mut f) = ([blank.clone(), blank.clone()], [blank.clone(), blank]);
        let mut se = 0.0;
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                for c in 0..3 {
                    let b = beta(x, y, c);
                    se += b * b;
                    for half in 0..2 {
                        let nq = rng.next();
                        let nf = rho * nq + (1.0 - rho * rho).sqrt() * rng.next();
                        q[half].pixels[i][c] = (0.5 + b / r + sq * nq) as f32;
                        f[half].pixels[i][c] = (0.5 + b + sf * nf) as f32;
                    }
                }
            }
        }
        (q, f, (se / (w * h * 3) as f64).sqrt())
    }

    fn bound(q: &[Image; 2], f: &[Image; 2]) -> ReferenceBias {
        bias_bound([&q[0], &q[1]], [&f[0], &f[1]], ALPHA).unwrap()
    }

    #[test]
    fn extrapolation_is_the_power_laws() {
        let k = 4f64.powf(-0.3) / (1.0 - 4f64.powf(-0.3));
        assert!((k - 1.0 / (4f64.powf(0.3) - 1.0)).abs() < 1e-12);
        let (q, f, _) = synthetic(16, 16, |_, _, _| 0.0, 1);
        assert!((bound(&q, &f).bias_extrapolation - k).abs() < 1e-6);
    }

    #[test]
    fn a_known_bias_is_estimated_and_covered() {
        let beta = |x: u32, y: u32, c: usize| {
            0.01 * (1.0 + 0.5 * (x as f64 / 7.0).sin() * (y as f64 / 5.0).cos()) * (1 + c) as f64
        };
        let (q, f, truth) = synthetic(128, 96, beta, 7);
        let b = bound(&q, &f);
        assert!(b.bias_resolved, "{b:?}");
        assert!(
            (b.bias_estimate_rmse - truth).abs() < 0.1 * truth,
            "estimate {} against the true {truth}",
            b.bias_estimate_rmse
        );
        assert!(b.bias_bound_rmse_95 >= truth, "{b:?} against {truth}");
        assert!(b.bias_bound_rmse_95 < 1.3 * truth, "{b:?} against {truth}");
        // Without the noise removed the change would overstate it many times.
        let (fm, qm) = (Image::average(&f), Image::average(&q));
        let raw = rmse(&fm, &qm).unwrap() * b.bias_extrapolation;
        assert!(raw > 2.0 * truth, "raw {raw} against {truth}");
    }

    #[test]
    fn pure_noise_is_not_resolved_and_its_bound_is_not_zero() {
        let (q, f, truth) = synthetic(128, 96, |_, _, _| 0.0, 11);
        assert_eq!(truth, 0.0);
        let b = bound(&q, &f);
        assert!(!b.bias_resolved, "{b:?}");
        assert!(b.bias_bound_rmse_95 > 0.0, "{b:?}");
        assert!(b.bias_bound_rmse_95 > b.bias_estimate_rmse, "{b:?}");
        // The bound is the noise's size: D's sd over sqrt(2) (the mean of two
        // halves), scaled by k, then shrunk by the pixels' count.
        assert!(b.bias_bound_rmse_95 < 0.01, "{b:?}");
    }

    #[test]
    fn the_bound_covers_a_bias_near_the_noise_at_least_nine_times_in_ten() {
        let mut covered = 0;
        let trials = 40;
        for seed in 0..trials {
            let beta = |x: u32, _: u32, _: usize| if x < 32 { 0.004 } else { -0.002 };
            let (q, f, truth) = synthetic(64, 48, beta, 1000 + seed);
            covered += (bound(&q, &f).bias_bound_rmse_95 >= truth) as u32;
        }
        assert!(covered >= 36, "covered {covered} of {trials}");
    }

    #[test]
    fn images_of_different_sizes_or_one_pixel_are_refused() {
        let (q, f, _) = synthetic(16, 16, |_, _, _| 0.0, 3);
        let (small, _, _) = synthetic(8, 16, |_, _, _| 0.0, 3);
        assert!(bias_bound([&q[0], &small[1]], [&f[0], &f[1]], ALPHA).is_err());
        let (q, f, _) = synthetic(1, 1, |_, _, _| 0.0, 3);
        assert!(bias_bound([&q[0], &q[1]], [&f[0], &f[1]], ALPHA).is_err());
    }

    #[test]
    fn old_references_still_read_and_new_ones_round_trip() {
        let old: ReferenceInfo = serde_json::from_str(include_str!(
            "../../../reference_images/glass_ball.sppm.json"
        ))
        .unwrap();
        assert!(old.bias.is_none());
        let (q, f, _) = synthetic(16, 16, |_, _, _| 0.01, 5);
        let info = ReferenceInfo {
            bias: Some(bound(&q, &f)),
            ..old
        };
        let json = serde_json::to_value(&info).unwrap();
        assert!(json["bias_bound_rmse_95"].as_f64().unwrap() > 0.0);
        assert!(json.get("residual_bias_rmse").is_none());
        let back: ReferenceInfo = serde_json::from_value(json).unwrap();
        assert_eq!(back.bias, info.bias);
    }
}
