//! `photonmap bench mitsuba`: photonmap's SPPM at its defaults against what
//! a user would pick instead, Mitsuba 3, on the same machine for the same
//! wall times (`--seconds`), all compared with independent ground truth
//! (reference_images/truth/: Mitsuba plus a separate light tracer, on the
//! pixels of its interior mask); relative RMSE against seconds for each
//! method as `convergence.svg`. `--spp` adds photonmap's one-map render at
//! its defaults, and gives SPPM and Mitsuba each render's wall time. The
//! scene is exported (camera, shapes as meshes, spheres and cylinders,
//! materials, lights) for `mitsuba_render.py`, which this binary embeds and
//! runs with `--python`; Mitsuba itself is not a dependency of this program
//! or its tests (`pip install mitsuba`; its LLVM back end needs libLLVM 16
//! or newer, named by DRJIT_LIBLLVM_PATH where the system's is older).

//!
//! Running Mitsuba is in `runner`, what every image is scored against in
//! `score`, the table and plot in `report`.

mod report;
mod runner;
mod score;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;
use clap::Args;
use serde::Serialize;

use photonmap::gpu::{Gpu, Platform};
use photonmap::render::sppm::{render_sppm, SppmOptions};
use photonmap::render::{render, EstimatePass, RenderObserver};
use photonmap::scene::{embedded, Scene};

use super::output::{folder, BenchOutput};
use super::reference::reference_options;
use super::scene::{stem, SEED};
use crate::cli::args::in_range;
use runner::Taken;
use score::{Bench, Target};

#[derive(Args)]
pub struct MitsubaBenchArgs {
    /// Scene file or embedded name.
    #[arg(long)]
    pub scene: PathBuf,
    /// The image every render is compared with (linear EXR; default
    /// reference_images/truth/<scene>.exr where it exists, else the scene's
    /// SPPM reference as `bench accuracy` finds it). Everything renders at
    /// its size, which must be the scene's divided by a whole number.
    #[arg(long, value_name = "EXR", conflicts_with = "mitsuba_reference")]
    pub reference: Option<PathBuf>,
    /// For scenes without committed truth: the reference is Mitsuba's path
    /// tracer, two independent runs of this many seconds each, averaged
    /// (`reference.exr` in --out); their difference gives its noise. Path
    /// tracing converges to the exact image, but slowly where light reaches
    /// diffuse surfaces through mirrors or glass, and never from a point
    /// light through them: use it for scenes it handles.
    #[arg(long, value_name = "SECONDS", value_parser = budget_seconds)]
    pub mitsuba_reference: Option<f64>,
    /// With --mitsuba-reference: render at the scene's size divided by this
    /// (1..=16; the size must divide).
    #[arg(long, default_value_t = 2, value_parser = in_range(1, 16), requires = "mitsuba_reference")]
    pub scale: u32,
    /// Only pixels where this PNG (the reference's size) is bright count
    /// (default with the default truth: its interior mask,
    /// reference_images/truth/<scene>_interior_mask.png; otherwise every
    /// pixel).
    #[arg(long, value_name = "PNG")]
    pub mask: Option<PathBuf>,
    /// Wall-time budgets in seconds (e.g. 30,60,120): photonmap's SPPM at
    /// its defaults and each Mitsuba integrator render for each; the longest
    /// also records the convergence curves.
    #[arg(long, value_delimiter = ',', value_parser = budget_seconds)]
    pub seconds: Vec<f64>,
    /// photonmap's one-map render at its defaults with this many eye
    /// samples per pixel (1..=1024), one render each; SPPM and Mitsuba get
    /// each render's wall time (default 1 without --seconds, none with it).
    #[arg(long, value_delimiter = ',', value_parser = in_range(1, 1024))]
    pub spp: Vec<u32>,
    /// Mitsuba's integrators: path (path tracing with next-event estimation),
    /// ptracer (light tracing, which finds a point light's caustic).
    #[arg(long, value_delimiter = ',', default_values_t = ["path".to_string(), "ptracer".to_string()])]
    pub integrators: Vec<String>,
    /// Mitsuba's variant.
    #[arg(long, default_value = "llvm_ad_rgb")]
    pub variant: String,
    /// The Python that imports mitsuba.
    #[arg(long, default_value = "python3")]
    pub python: String,
    /// Mitsuba's longest path (max_depth: -1, Mitsuba's default, leaves
    /// paths to Russian roulette; else 1..=1024).
    #[arg(long, default_value_t = -1, allow_negative_numbers = true, value_parser = max_depth)]
    pub max_depth: i32,
    /// Folder for the export, the script, each image, mitsuba.json and
    /// convergence.svg (default photonmap-out/mitsuba/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// Mitsuba's max_depth: -1 (unbounded) or 1..=1024.
fn max_depth(s: &str) -> Result<i32, String> {
    match s.trim().parse::<i32>() {
        Ok(v) if v == -1 || (1..=1024).contains(&v) => Ok(v),
        _ => Err(format!("{s}: give -1 (no limit) or a depth in 1..=1024")),
    }
}

/// A budget: a positive number of seconds, at most a day.
fn budget_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 86_400.0 => Ok(v),
        _ => Err(format!("{s}: give seconds above 0 (at most 86400)")),
    }
}

#[derive(Serialize, Clone, Debug)]
pub struct Row {
    pub renderer: String,
    /// The wall time it was given: a --seconds budget, or the one-map
    /// render's time with --spp (None for that render itself).
    pub budget: Option<f64>,
    /// Wall seconds it took (Mitsuba: its first render call on, JIT
    /// included; SPPM: setup included).
    pub seconds: f64,
    /// Samples per pixel (Mitsuba, the one-map render) or iterations (SPPM).
    pub samples: u32,
    /// Camera paths a second: samples x width x height / seconds.
    pub paths_per_second: f64,
    /// SPPM: photons emitted a second.
    pub photons_per_second: Option<f64>,
    /// RMSE over the reference's mean, on the mask's pixels: the headline.
    pub rel_rmse: f64,
    /// The image's mean over the reference's, same pixels.
    pub energy: f64,
    /// Mean of (a - b)^2 / (b^2 + 0.01).
    pub rel_mse: f64,
    pub rmse: f64,
    /// PNG in the out folder (the EXR beside it has the same stem).
    pub image: String,
}

/// One image along a method's longest run.
#[derive(Serialize, Clone, Debug)]
pub struct CurvePoint {
    pub seconds: f64,
    pub samples: u32,
    pub rel_rmse: f64,
    pub energy: f64,
    pub rel_mse: f64,
    pub image: String,
}

/// Error against wall time for one method, along its longest run.
#[derive(Serialize, Clone, Debug)]
pub struct Curve {
    pub renderer: String,
    pub points: Vec<CurvePoint>,
}

#[derive(Serialize)]
pub struct MitsubaBench {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference: String,
    /// "truth" (the committed ground truth), "given" (--reference) or "SPPM
    /// reference".
    pub reference_kind: String,
    pub mask: Option<String>,
    pub pixels_compared: usize,
    /// The reference's own relative noise: the truth's noise.json figure
    /// (full-size image), or a --mitsuba-reference's from its two runs.
    /// Nothing is measured more finely.
    pub truth_noise: Option<f64>,
    pub gl_renderer: String,
    pub variant: String,
    pub max_depth: i32,
    pub budgets: Vec<f64>,
    pub rows: Vec<Row>,
    pub curves: Vec<Curve>,
    pub convergence_plot: String,
}

/// Keeps SPPM's running image after the first iteration past each mark
/// (seconds on the caller's clock, this observer's own time not counted).
struct Checkpoints {
    marks: Vec<f64>,
    start: Instant,
    own: f64,
    taken: Vec<Taken>,
}

impl Checkpoints {
    fn new(mut marks: Vec<f64>) -> Self {
        marks.sort_by(f64::total_cmp);
        Self {
            marks,
            start: Instant::now(),
            own: 0.0,
            taken: Vec::new(),
        }
    }

    fn seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64() - self.own
    }
}

impl RenderObserver for Checkpoints {
    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> photonmap::Result<()> {
        let t = self.seconds();
        if pass.finished || self.marks.first().is_none_or(|&m| t < m) {
            return Ok(());
        }
        let t0 = Instant::now();
        self.marks.retain(|&m| m > t);
        self.taken.push((t, pass.pass + 1, pass.image()?));
        self.own += t0.elapsed().as_secs_f64();
        Ok(())
    }
}

/// The longest run's checkpoints: 1/32, 1/16, .., 1/2 of its budget.
fn marks(budget: f64) -> Vec<f64> {
    (1..=5)
        .rev()
        .map(|k| budget / f64::from(1u32 << k))
        .collect()
}

/// A budget's label in file names: "30s", "2.5s", or "1spp" (--spp).
fn label(budget: f64, spp: Option<u32>) -> String {
    match spp {
        Some(n) => format!("{n}spp"),
        None => format!("{budget}s"),
    }
}

/// SPPM at its defaults and each Mitsuba integrator for `budget` seconds:
/// their rows, and their curves when `longest`.
fn race(
    a: &MitsubaBenchArgs,
    (gpu, scene, scale): (&Gpu, &Scene, u32),
    bench: &Bench,
    (budget, spp): (f64, Option<u32>),
    longest: bool,
    (rows, curves): (&mut Vec<Row>, &mut Vec<Curve>),
) -> Result<()> {
    let progress = a.output.progress();
    let tag = label(budget, spp);
    let checkpoints = if longest { marks(budget) } else { Vec::new() };
    progress(&format!("photonmap SPPM, {budget:.1} s"));
    let sppm = SppmOptions {
        iterations: 1_000_000,
        seconds: Some(budget),
        ..SppmOptions::default()
    };
    let o = reference_options(scene, scale, SEED);
    let mut watch = Checkpoints::new(checkpoints.clone());
    let s = render_sppm(gpu, scene, &o, &sppm, &mut watch)?;
    let taken = (watch.seconds(), s.iterations, s.image);
    let stem = format!("photonmap_sppm_{tag}");
    let row = bench.row(
        "photonmap SPPM",
        Some(budget),
        &taken,
        Some(s.photons_emitted),
        &stem,
    )?;
    if longest {
        curves.push(bench.curve("photonmap SPPM", &stem, &watch.taken, &row)?);
    }
    rows.push(row);
    for integrator in &a.integrators {
        progress(&format!("Mitsuba {integrator}, {budget:.1} s"));
        let (taken, along) =
            runner::render_mitsuba(a, bench.dir, integrator, budget, &checkpoints, 0)?;
        let (label, stem) = (
            format!("Mitsuba {integrator}"),
            format!("mitsuba_{integrator}_{tag}"),
        );
        let row = bench.row(&label, Some(budget), &taken, None, &stem)?;
        if longest {
            curves.push(bench.curve(&label, &stem, &along, &row)?);
        }
        rows.push(row);
    }
    Ok(())
}

/// Everything before the races: the reference (checked, or made by
/// Mitsuba with --mitsuba-reference), the output folder, and the export and
/// script Mitsuba runs from. Returns the reference, its scale and the folder.
fn prepare(a: &MitsubaBenchArgs, scene: &Scene, name: &str) -> Result<(Target, u32, PathBuf)> {
    let given = match a.mitsuba_reference {
        None => Some(score::target(a, scene, name)?),
        Some(_) => None,
    };
    let (width, height) = match &given {
        Some((t, _)) => (t.image.width, t.image.height),
        None => score::mitsuba_reference_size(a, scene)?,
    };
    let mitsuba_mask = match given {
        Some(_) => None,
        None => score::mask_of_size(a, width, height)?,
    };
    runner::check_mitsuba(a)?;
    let dir = folder(a.out.as_deref(), "mitsuba", Some(name))?;
    runner::write_inputs(&dir, scene, (width, height), a.max_depth)?;
    let (target, scale) = match given {
        Some(t) => t,
        None => score::mitsuba_target(a, &dir, mitsuba_mask, &a.output.progress())?,
    };
    Ok((target, scale, dir))
}

pub fn run(a: &MitsubaBenchArgs, platform: Platform) -> Result<()> {
    let scene = embedded::load_path_or_name(&a.scene)?;
    let name = stem(&a.scene);
    let (target, scale, dir) = prepare(a, &scene, &name)?;
    let (width, height) = (target.image.width, target.image.height);
    let progress = a.output.progress();
    let gpu = crate::cli::gpu(platform)?;
    let bench = Bench {
        dir: &dir,
        target: &target,
        width,
        height,
    };
    let mut rows = Vec::new();
    // Budgets: each one-map render's time (--spp), then --seconds.
    let mut budgets: Vec<(f64, Option<u32>)> = Vec::new();
    let mut spp = a.spp.clone();
    if spp.is_empty() && a.seconds.is_empty() {
        spp.push(1);
    }
    spp.sort_unstable();
    spp.dedup();
    for &n in &spp {
        progress(&format!("photonmap, {n} spp"));
        let mut o = reference_options(&scene, scale, SEED);
        o.spp = n;
        let t = Instant::now();
        let out = render(&gpu, &scene, &o, &mut ())?;
        let taken = (t.elapsed().as_secs_f64(), n, out.image);
        rows.push(bench.row(
            "photonmap",
            None,
            &taken,
            None,
            &format!("photonmap_{n}spp"),
        )?);
        budgets.push((taken.0, Some(n)));
    }
    let mut seconds = a.seconds.clone();
    seconds.sort_by(f64::total_cmp);
    seconds.dedup();
    budgets.extend(seconds.iter().map(|&s| (s, None)));
    let longest = (0..budgets.len()).max_by(|&i, &j| budgets[i].0.total_cmp(&budgets[j].0));
    let mut curves = Vec::new();
    for (i, &budget) in budgets.iter().enumerate() {
        let at = (&gpu, &scene, scale);
        race(
            a,
            at,
            &bench,
            budget,
            Some(i) == longest,
            (&mut rows, &mut curves),
        )?;
    }
    let report = MitsubaBench {
        scene: name,
        width,
        height,
        reference: target.path.display().to_string(),
        reference_kind: target.kind.into(),
        mask: target.mask.as_ref().map(|m| m.0.display().to_string()),
        pixels_compared: target.mask.as_ref().map_or((width * height) as usize, |m| {
            m.1.iter().filter(|&&k| k).count()
        }),
        truth_noise: target.noise,
        gl_renderer: gpu.capabilities().gl_renderer,
        variant: a.variant.clone(),
        max_depth: a.max_depth,
        budgets: budgets.iter().map(|b| b.0).collect(),
        rows,
        curves,
        convergence_plot: report::PLOT_FILE.into(),
    };
    report::write(&dir, &target, &report)?;
    runner::remove_script(&dir);
    a.output.print(&report, |r| {
        report::print_table(r);
        println!("wrote {}", dir.display());
    })
}
