//! `photonmap compare`: error metrics between two linear images, and
//! thresholds that make it fail a CI job (exit code 1).

use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::Args;

use photonmap::image::write_atomically;
use photonmap::metrics::{compare, false_colour, flip, fraction_beyond};
use photonmap::render::Image;

/// Compare two linear EXR images (the second is the reference): RMSE,
/// relative MSE, SSIM, FLIP and the pixels beyond a tolerance. With a
/// --fail-* threshold it exits 1 when a threshold fails, writing the
/// difference image (--diff, or photonmap-out/compare/<image>.diff.png).
#[derive(Args)]
pub struct CompareArgs {
    pub image: PathBuf,
    pub reference: PathBuf,
    /// Only pixels where this PNG (same size) is bright (> 50%) count.
    #[arg(long)]
    pub mask: Option<PathBuf>,
    /// Write |a - b| / (|b| + 0.01) as a false-colour PNG (black 0 .. red >= 1).
    #[arg(long, value_name = "PNG")]
    pub diff: Option<PathBuf>,
    /// Fail when the RMSE (linear) exceeds X.
    #[arg(long, value_name = "X")]
    pub fail_rmse: Option<f64>,
    /// Fail when the relative MSE exceeds X.
    #[arg(long, value_name = "X")]
    pub fail_relmse: Option<f64>,
    /// Fail when the SSIM falls below X.
    #[arg(long, value_name = "X")]
    pub fail_ssim: Option<f64>,
    /// Fail when the mean FLIP exceeds X (0 identical .. 1).
    #[arg(long, value_name = "X")]
    pub fail_flip: Option<f64>,
    /// A pixel fails when a channel differs by more than T (idiff's --fail).
    #[arg(long = "fail", value_name = "T")]
    pub fail_threshold: Option<f32>,
    /// With --fail: the percentage of failing pixels allowed (default 0).
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub fail_percent: f64,
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize)]
struct Report {
    image: String,
    reference: String,
    pixels_compared: usize,
    rmse: f64,
    rel_mse: f64,
    /// RMSE over the reference's mean (how ground truth is quoted).
    rel_rmse: f64,
    /// The image's mean over the reference's, same pixels.
    energy: f64,
    ssim: f64,
    flip: f64,
    /// Percentage of pixels with a channel beyond --fail (when given).
    percent_beyond: Option<f64>,
    /// Every threshold given and whether it held.
    checks: Vec<Check>,
    passed: bool,
    diff: Option<String>,
}

#[derive(serde::Serialize)]
struct Check {
    metric: String,
    limit: f64,
    value: f64,
    passed: bool,
}

pub fn run(args: &CompareArgs) -> Result<()> {
    if let Some(d) = &args.diff {
        super::check_output(d, "png", "--diff")?;
    }
    let a = Image::read_exr(&args.image)?;
    let b = Image::read_exr(&args.reference)?;
    let mask = args.mask.as_ref().map(|p| read_mask(p, &a)).transpose()?;
    let metrics = compare(&a, &b, mask.as_deref())?;
    let flip = flip(&a, &b)?;
    let percent_beyond = args
        .fail_threshold
        .map(|t| fraction_beyond(&a, &b, t).map(|f| 100.0 * f))
        .transpose()?;
    let mut checks = Vec::new();
    let mut check = |metric: &str, limit: Option<f64>, value: f64, higher_is_worse: bool| {
        if let Some(limit) = limit {
            let passed = if higher_is_worse {
                value <= limit
            } else {
                value >= limit
            };
            checks.push(Check {
                metric: metric.into(),
                limit,
                value,
                passed,
            });
        }
    };
    check("rmse", args.fail_rmse, metrics.rmse, true);
    check("rel_mse", args.fail_relmse, metrics.rel_mse, true);
    check("ssim", args.fail_ssim, metrics.ssim, false);
    check("flip", args.fail_flip, flip, true);
    if let Some(p) = percent_beyond {
        check("percent_beyond", Some(args.fail_percent), p, true);
    }
    let passed = checks.iter().all(|c| c.passed);
    let diff = match (&args.diff, passed) {
        (Some(d), _) => Some(d.clone()),
        (None, false) => {
            let dir = super::out_dir("compare");
            std::fs::create_dir_all(&dir)?;
            let stem = args
                .image
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            Some(dir.join(format!("{stem}.diff.png")))
        }
        (None, true) => None,
    };
    if let Some(d) = &diff {
        write_atomically(d, &false_colour(&a, &b).png_bytes()?)?;
    }
    let report = Report {
        image: args.image.display().to_string(),
        reference: args.reference.display().to_string(),
        pixels_compared: metrics.pixels_compared,
        rmse: metrics.rmse,
        rel_mse: metrics.rel_mse,
        rel_rmse: metrics.rel_rmse,
        energy: metrics.energy,
        ssim: metrics.ssim,
        flip,
        percent_beyond,
        checks,
        passed,
        diff: diff.map(|d| d.display().to_string()),
    };
    if args.json {
        super::print_json(&report)?;
    } else {
        println!("pixels compared  {}", report.pixels_compared);
        println!("RMSE (linear)    {:.6}", report.rmse);
        println!("relative MSE     {:.6}", report.rel_mse);
        println!("RMSE / mean      {:.6}", report.rel_rmse);
        println!("energy ratio     {:.6}", report.energy);
        println!("SSIM (luminance) {:.6}", report.ssim);
        println!("FLIP (mean)      {:.6}", report.flip);
        if let Some(p) = report.percent_beyond {
            println!("beyond --fail    {p:.4}% of pixels");
        }
        for c in &report.checks {
            println!(
                "{} {:<15} {:.6} against {:.6}",
                if c.passed { "pass" } else { "FAIL" },
                c.metric,
                c.value,
                c.limit
            );
        }
    }
    if !report.passed {
        let failed: Vec<&str> = report
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.metric.as_str())
            .collect();
        bail!(
            "the images differ beyond the thresholds ({}); difference image: {}",
            failed.join(", "),
            report.diff.as_deref().unwrap_or("-")
        );
    }
    Ok(())
}

/// A PNG mask of the image's size: bright pixels count.
pub(crate) fn read_mask(path: &std::path::Path, image: &Image) -> Result<Vec<bool>> {
    let m = ::image::open(path)
        .map_err(|e| anyhow!("cannot read the mask {}: {e}", path.display()))?
        .to_luma8();
    if m.dimensions() != (image.width, image.height) {
        bail!(
            "--mask {}: {} x {} pixels, the images are {} x {}",
            path.display(),
            m.width(),
            m.height(),
            image.width,
            image.height
        );
    }
    Ok(m.pixels().map(|p| p[0] > 127).collect())
}
