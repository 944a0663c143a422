//! `photonmap compare`: error metrics between two linear images, and two
//! tiers of thresholds, as OpenImageIO's idiff has: a --warn-* one that does
//! not hold prints a warning (exit 0), a --fail-* one fails a CI job (exit 1).

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use clap::{Args, ValueEnum};

use photonmap::bench::regions::{masked_rectangles, region_energies, Rectangle, RegionEnergy};
use photonmap::image::write_all_atomically;
use photonmap::metrics::{compare, false_colour, flip_map, fraction_beyond, FLIP_PERCENTILES};
use photonmap::render::Image;

use super::ci_report::{self, Case, Picture};

/// Compare two linear EXR images (the second is the reference): RMSE,
/// relative MSE, SSIM, FLIP's mean and percentiles, and the pixels beyond a
/// tolerance. A --fail-* threshold that does not hold makes it exit 1, a
/// --warn-* one prints a warning; either way it writes the difference image
/// (--diff, or photonmap-out/compare/<image>.diff.png).
#[derive(Args)]
pub struct CompareArgs {
    pub image: PathBuf,
    pub reference: PathBuf,
    /// Only pixels where this PNG (same size) is bright (> 50%) count (not FLIP).
    #[arg(long)]
    pub mask: Option<PathBuf>,
    /// Also report the energy (the image's mean over the reference's) in a
    /// rectangle: NAME=X0:X1:Y0:Y1, columns X0..X1 and rows Y0..Y1, row 0 at
    /// the top, ends excluded, less what --mask leaves out. Repeat it for more.
    #[arg(long, value_name = "NAME=X0:X1:Y0:Y1", value_parser = rectangle)]
    pub region: Vec<Rectangle>,
    /// Write the difference image as a PNG: FLIP's error map in its magma
    /// colour map when a FLIP threshold is given, else |a - b| / (|b| + 0.01)
    /// in false colour (black 0 .. red >= 1); --diff-map chooses.
    #[arg(long, value_name = "PNG")]
    pub diff: Option<PathBuf>,
    /// The difference image: flip (FLIP's error map, magma: black 0 .. pale
    /// yellow 1) or relative (|a - b| / (|b| + 0.01) in false colour).
    #[arg(long, value_enum)]
    pub diff_map: Option<DiffMap>,
    #[command(flatten)]
    pub fail: FailArgs,
    #[command(flatten)]
    pub warn: WarnArgs,
    /// Write a JUnit XML report (one test case) to this file.
    #[arg(long, value_name = "XML")]
    pub junit: Option<PathBuf>,
    /// Write an HTML report to this file: the image, the reference and FLIP's
    /// error map side by side, with the figures (self-contained).
    #[arg(long, value_name = "HTML")]
    pub html: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

/// `--region`'s NAME=X0:X1:Y0:Y1.
fn rectangle(s: &str) -> std::result::Result<Rectangle, String> {
    s.parse()
}

#[derive(Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DiffMap {
    Flip,
    Relative,
}

/// The thresholds that fail (exit 1).
#[derive(Args)]
pub struct FailArgs {
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
    /// Fail when FLIP's P-th (weighted) percentile exceeds X: 99:0.3
    /// (P in (0, 100), X in [0, 1]; repeatable).
    #[arg(long, value_name = "P:X", value_parser = percentile_limit)]
    pub fail_flip_percentile: Vec<(f64, f64)>,
    /// A pixel fails when a channel differs by more than T (idiff's --fail).
    #[arg(long = "fail", value_name = "T")]
    pub fail_threshold: Option<f32>,
    /// With --fail: the percentage of failing pixels allowed (default 0).
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub fail_percent: f64,
}

/// The thresholds that only warn (exit 0).
#[derive(Args)]
pub struct WarnArgs {
    /// Warn when the RMSE (linear) exceeds X.
    #[arg(long, value_name = "X")]
    pub warn_rmse: Option<f64>,
    /// Warn when the relative MSE exceeds X.
    #[arg(long, value_name = "X")]
    pub warn_relmse: Option<f64>,
    /// Warn when the SSIM falls below X.
    #[arg(long, value_name = "X")]
    pub warn_ssim: Option<f64>,
    /// Warn when the mean FLIP exceeds X.
    #[arg(long, value_name = "X")]
    pub warn_flip: Option<f64>,
    /// Warn when FLIP's P-th (weighted) percentile exceeds X (repeatable).
    #[arg(long, value_name = "P:X", value_parser = percentile_limit)]
    pub warn_flip_percentile: Vec<(f64, f64)>,
    /// A pixel warns when a channel differs by more than T (idiff's --warn).
    #[arg(long = "warn", value_name = "T")]
    pub warn_threshold: Option<f32>,
    /// With --warn: the percentage of such pixels allowed (default 0).
    #[arg(long, value_name = "P", default_value_t = 0.0)]
    pub warn_percent: f64,
}

/// `P:X`: a percentile in (0, 100) and a FLIP limit in [0, 1].
fn percentile_limit(s: &str) -> Result<(f64, f64), String> {
    let (p, x) = s.split_once(':').ok_or_else(|| {
        format!("{s}: give P:X, as in 99:0.3 (FLIP's 99th percentile at most 0.3)")
    })?;
    let p: f64 = p
        .trim()
        .parse()
        .map_err(|_| format!("{s}: the percentile P must be a number in (0, 100)"))?;
    let x: f64 = x
        .trim()
        .parse()
        .map_err(|_| format!("{s}: the limit X must be a number in [0, 1]"))?;
    if !(p > 0.0 && p < 100.0) {
        return Err(format!("{s}: the percentile {p} is outside (0, 100)"));
    }
    if !(0.0..=1.0).contains(&x) {
        return Err(format!("{s}: the limit {x} is outside [0, 1]"));
    }
    Ok((p, x))
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
    /// FLIP's mean.
    flip: f64,
    /// FLIP's weighted percentiles: p50, p90, p95, p99.
    flip_percentiles: std::collections::BTreeMap<String, f64>,
    /// Percentage of pixels with a channel beyond --fail (when given).
    percent_beyond: Option<f64>,
    /// Percentage of pixels with a channel beyond --warn (when given).
    percent_beyond_warn: Option<f64>,
    /// Every threshold given and whether it held.
    checks: Vec<Check>,
    /// No fail-tier threshold failed.
    passed: bool,
    /// A warn-tier threshold did not hold.
    warned: bool,
    diff: Option<String>,
    /// The energy in each --region.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    regions: Vec<RegionEnergy>,
}

#[derive(serde::Serialize)]
struct Check {
    metric: String,
    /// "fail" or "warn".
    tier: &'static str,
    limit: f64,
    value: f64,
    passed: bool,
}

/// The metrics a threshold can name, measured once.
struct Measured {
    m: photonmap::metrics::Metrics,
    flip: photonmap::metrics::FlipMap,
}

/// One tier's thresholds.
struct Thresholds<'a> {
    tier: &'static str,
    rmse: Option<f64>,
    relmse: Option<f64>,
    ssim: Option<f64>,
    flip: Option<f64>,
    percentiles: &'a [(f64, f64)],
    /// The percentage of pixels beyond the tier's T, and the percentage allowed.
    beyond: Option<(f64, f64)>,
}

impl Measured {
    /// Each threshold of one tier as a check.
    fn checks(&self, t: &Thresholds) -> Vec<Check> {
        let mut out = Vec::new();
        let mut check = |metric: String, limit: Option<f64>, value: f64, higher_is_worse: bool| {
            if let Some(limit) = limit {
                let passed = if higher_is_worse {
                    value <= limit
                } else {
                    value >= limit
                };
                out.push(Check {
                    metric,
                    tier: t.tier,
                    limit,
                    value,
                    passed,
                });
            }
        };
        check("rmse".into(), t.rmse, self.m.rmse, true);
        check("rel_mse".into(), t.relmse, self.m.rel_mse, true);
        check("ssim".into(), t.ssim, self.m.ssim, false);
        check("flip".into(), t.flip, self.flip.mean, true);
        for &(p, x) in t.percentiles {
            check(format!("flip_p{p}"), Some(x), self.flip.percentile(p), true);
        }
        if let Some((percent, allowed)) = t.beyond {
            check("percent_beyond".into(), Some(allowed), percent, true);
        }
        out
    }
}

pub fn run(args: &CompareArgs) -> Result<()> {
    if let Some(d) = &args.diff {
        super::check_output(d, "png", "--diff")?;
    }
    ci_report::check_paths(args.junit.as_deref(), args.html.as_deref())?;
    let wall = std::time::Instant::now();
    let a = Image::read_exr(&args.image)?;
    let b = Image::read_exr(&args.reference)?;
    let mask = args.mask.as_ref().map(|p| read_mask(p, &a)).transpose()?;
    let regions = masked_rectangles(&args.region, (a.width, a.height), mask.as_deref())
        .map_err(|e| anyhow!("{e} of {}", args.image.display()))?;
    let measured = Measured {
        m: compare(&a, &b, mask.as_deref())?,
        flip: flip_map(&a, &b)?,
    };
    let beyond = |t: Option<f32>| -> Result<Option<f64>> {
        Ok(t.map(|t| fraction_beyond(&a, &b, t).map(|f| 100.0 * f))
            .transpose()?)
    };
    let (percent_beyond, percent_beyond_warn) = (
        beyond(args.fail.fail_threshold)?,
        beyond(args.warn.warn_threshold)?,
    );
    let (f, w) = (&args.fail, &args.warn);
    let mut checks = measured.checks(&Thresholds {
        tier: "fail",
        rmse: f.fail_rmse,
        relmse: f.fail_relmse,
        ssim: f.fail_ssim,
        flip: f.fail_flip,
        percentiles: &f.fail_flip_percentile,
        beyond: percent_beyond.map(|p| (p, f.fail_percent)),
    });
    checks.extend(measured.checks(&Thresholds {
        tier: "warn",
        rmse: w.warn_rmse,
        relmse: w.warn_relmse,
        ssim: w.warn_ssim,
        flip: w.warn_flip,
        percentiles: &w.warn_flip_percentile,
        beyond: percent_beyond_warn.map(|p| (p, w.warn_percent)),
    }));
    let failed = names(&checks, "fail");
    let warned = names(&checks, "warn");
    let diff = diff_path(args, failed.is_empty() && warned.is_empty());
    let report = Report {
        image: args.image.display().to_string(),
        reference: args.reference.display().to_string(),
        pixels_compared: measured.m.pixels_compared,
        rmse: measured.m.rmse,
        rel_mse: measured.m.rel_mse,
        rel_rmse: measured.m.rel_rmse,
        energy: measured.m.energy,
        ssim: measured.m.ssim,
        flip: measured.flip.mean,
        flip_percentiles: FLIP_PERCENTILES
            .iter()
            .map(|&p| (format!("p{p}"), measured.flip.percentile(p)))
            .collect(),
        percent_beyond,
        percent_beyond_warn,
        passed: failed.is_empty(),
        warned: !warned.is_empty(),
        checks,
        diff: diff.as_ref().map(|d| d.display().to_string()),
        regions: region_energies(&regions, &a, &b),
    };
    let case = case(&report, &measured, &a, &b, wall.elapsed().as_secs_f64())?;
    write_outputs(args, &report, &measured, &a, &b, &case)?;
    print(args, &report)?;
    let diff_shown = report.diff.as_deref().unwrap_or("-");
    if !warned.is_empty() {
        eprintln!(
            "warning: the images differ beyond the warning thresholds ({}); difference image: {diff_shown}",
            warned.join(", ")
        );
    }
    if !failed.is_empty() {
        bail!(
            "the images differ beyond the thresholds ({}); difference image: {diff_shown}",
            failed.join(", ")
        );
    }
    Ok(())
}

/// The metrics of one tier's checks that did not hold.
fn names(checks: &[Check], tier: &str) -> Vec<String> {
    checks
        .iter()
        .filter(|c| c.tier == tier && !c.passed)
        .map(|c| c.metric.clone())
        .collect()
}

/// --diff, or the default path when a threshold did not hold.
fn diff_path(args: &CompareArgs, all_held: bool) -> Option<PathBuf> {
    match (&args.diff, all_held) {
        (Some(d), _) => Some(d.clone()),
        (None, false) => {
            let stem = args
                .image
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            Some(super::out_dir("compare").join(format!("{stem}.diff.png")))
        }
        (None, true) => None,
    }
}

/// Whether a FLIP threshold was given (the difference image is then FLIP's).
fn flip_asked(args: &CompareArgs) -> bool {
    args.fail.fail_flip.is_some()
        || args.warn.warn_flip.is_some()
        || !args.fail.fail_flip_percentile.is_empty()
        || !args.warn.warn_flip_percentile.is_empty()
}

/// The difference image, the JUnit and the HTML report, all or nothing.
fn write_outputs(
    args: &CompareArgs,
    report: &Report,
    measured: &Measured,
    a: &Image,
    b: &Image,
    case: &Case,
) -> Result<()> {
    let mut files = ci_report::files(
        "compare",
        std::slice::from_ref(case),
        args.junit.as_deref(),
        args.html.as_deref(),
    )?;
    if let Some(d) = &report.diff {
        let d = Path::new(d);
        if args.diff.is_none() {
            std::fs::create_dir_all(d.parent().unwrap_or(Path::new(".")))?;
        }
        let flip = args.diff_map.unwrap_or(if flip_asked(args) {
            DiffMap::Flip
        } else {
            DiffMap::Relative
        }) == DiffMap::Flip;
        let png = if flip {
            measured.flip.magma_png()?
        } else {
            false_colour(a, b).png_bytes()?
        };
        files.push((d.to_path_buf(), png));
    }
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    write_all_atomically(&refs)?;
    Ok(())
}

/// The one case of the JUnit and HTML reports.
fn case(r: &Report, measured: &Measured, a: &Image, b: &Image, seconds: f64) -> Result<Case> {
    let shown = |c: &Check| format!("{} {:.6} against {:.6}", c.metric, c.value, c.limit);
    let of_tier = |tier: &str| -> Vec<String> {
        r.checks
            .iter()
            .filter(|c| c.tier == tier && !c.passed)
            .map(shown)
            .collect()
    };
    let failed = of_tier("fail");
    let mut figures = vec![
        ("reference".to_string(), r.reference.clone()),
        ("RMSE (linear)".into(), format!("{:.6}", r.rmse)),
        ("relative MSE".into(), format!("{:.6}", r.rel_mse)),
        ("SSIM".into(), format!("{:.6}", r.ssim)),
        ("FLIP mean".into(), format!("{:.6}", r.flip)),
    ];
    for (k, v) in &r.flip_percentiles {
        figures.push((format!("FLIP {k}"), format!("{v:.6}")));
    }
    for c in &r.checks {
        let verdict = if c.passed { "holds" } else { c.tier };
        figures.push((
            format!("{} threshold", c.tier),
            format!("{} ({verdict})", shown(c)),
        ));
    }
    Ok(Case {
        name: r.image.clone(),
        failure: (!failed.is_empty()).then(|| failed.join("; ")),
        warnings: of_tier("warn"),
        seconds,
        figures,
        pictures: vec![
            Picture {
                caption: "image".into(),
                png: a.png_bytes()?,
            },
            Picture {
                caption: "reference".into(),
                png: b.png_bytes()?,
            },
            Picture {
                caption: "FLIP error map (magma: black 0 .. pale yellow 1)".into(),
                png: measured.flip.magma_png()?,
            },
        ],
    })
}

fn print(args: &CompareArgs, report: &Report) -> Result<()> {
    if args.json {
        return super::print_json(report);
    }
    println!("pixels compared  {}", report.pixels_compared);
    println!("RMSE (linear)    {:.6}", report.rmse);
    println!("relative MSE     {:.6}", report.rel_mse);
    println!("RMSE / mean      {:.6}", report.rel_rmse);
    println!("energy ratio     {:.6}", report.energy);
    println!("SSIM (luminance) {:.6}", report.ssim);
    println!("FLIP (mean)      {:.6}", report.flip);
    for (k, v) in &report.flip_percentiles {
        println!("FLIP {k:<11} {v:.6}");
    }
    if let Some(p) = report.percent_beyond {
        println!("beyond --fail    {p:.4}% of pixels");
    }
    if let Some(p) = report.percent_beyond_warn {
        println!("beyond --warn    {p:.4}% of pixels");
    }
    for r in &report.regions {
        println!("energy in {} ({} pixels) {:.6}", r.name, r.pixels, r.energy);
    }
    for c in &report.checks {
        let verdict = match (c.passed, c.tier) {
            (true, _) => "pass",
            (false, "warn") => "WARN",
            (false, _) => "FAIL",
        };
        println!(
            "{verdict} {:<15} {:.6} against {:.6}",
            c.metric, c.value, c.limit
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
