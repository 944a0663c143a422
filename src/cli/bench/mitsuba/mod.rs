//! `photonmap bench mitsuba`: photonmap's progressive methods (SPPM and VCM,
//! `--methods`) at their defaults against what
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

mod args;
mod report;
mod runner;
mod score;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;

use photonmap::bench::regions::Region;
use photonmap::gpu::{Gpu, Platform};
use photonmap::render::sppm::{render_sppm, SppmOptions};
use photonmap::render::vcm::{render_vcm, VcmOptions};
use photonmap::render::{render, EstimatePass, RenderObserver};
use photonmap::scene::{embedded, Scene};

use super::output::{folder, stem};
use super::reference::reference_options;
use super::scene::SEED;
use report::{Curve, MitsubaBench, Row};
use runner::Taken;
use score::{Bench, Target};

pub use args::{MitsubaBenchArgs, ProgressiveMethod};
pub use runner::{check_variant, mitsuba_rates, MitsubaRates};

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

/// photonmap's progressive methods at their defaults and each Mitsuba
/// integrator for `budget` seconds: their rows, and their curves when
/// `longest`.
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
    let o = reference_options(scene, scale, SEED);
    for &method in &a.methods {
        let label = match method {
            ProgressiveMethod::Sppm => "photonmap SPPM",
            ProgressiveMethod::Vcm => "photonmap VCM",
        };
        progress(&format!("{label}, {budget:.1} s"));
        let mut watch = Checkpoints::new(checkpoints.clone());
        let (iterations, paths, image) = match method {
            ProgressiveMethod::Sppm => {
                let sppm = SppmOptions {
                    iterations: 1_000_000,
                    seconds: Some(budget),
                    ..SppmOptions::default()
                };
                let s = render_sppm(gpu, scene, &o, &sppm, &mut watch)?;
                (s.iterations, s.photons_emitted, s.image)
            }
            ProgressiveMethod::Vcm => {
                let vcm = VcmOptions {
                    iterations: 1_000_000,
                    seconds: Some(budget),
                    ..VcmOptions::default()
                };
                let v = render_vcm(gpu, scene, &o, &vcm, false, &mut watch)?;
                (v.iterations, v.light_paths, v.image)
            }
        };
        let taken = (watch.seconds(), iterations, image);
        let stem = format!("photonmap_{method}_{tag}");
        let row = bench.row(label, Some(budget), &taken, Some(paths), &stem)?;
        if longest {
            curves.push(bench.curve(label, &stem, &watch.taken, &row)?);
        }
        rows.push(row);
    }
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
/// script Mitsuba runs from. Returns the reference, its scale, the folder
/// and the `--region`s.
fn prepare(
    a: &MitsubaBenchArgs,
    scene: &Scene,
    name: &str,
) -> Result<(Target, u32, PathBuf, Vec<Region>)> {
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
    let mask = match &given {
        Some((t, _)) => t.mask.as_ref(),
        None => mitsuba_mask.as_ref(),
    };
    let regions = score::regions(a, (width, height), mask.map(|m| m.1.as_slice()))?;
    runner::check_mitsuba(a)?;
    let dir = folder(a.out.as_deref(), "mitsuba", Some(name))?;
    runner::write_inputs(&dir, scene, (width, height), a.max_depth)?;
    let (target, scale) = match given {
        Some(t) => t,
        None => score::mitsuba_target(a, &dir, mitsuba_mask, &a.output.progress())?,
    };
    Ok((target, scale, dir, regions))
}

pub fn run(a: &MitsubaBenchArgs, platform: Platform) -> Result<()> {
    let scene = embedded::load_path_or_name(&a.scene)?;
    let name = stem(&a.scene);
    let (target, scale, dir, regions) = prepare(a, &scene, &name)?;
    let (width, height) = (target.image.width, target.image.height);
    let progress = a.output.progress();
    let gpu = crate::cli::gpu(platform)?;
    let bench = Bench {
        dir: &dir,
        target: &target,
        regions: &regions,
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
    report::write(&dir, &report)?;
    runner::remove_script(&dir);
    a.output.print(&report, |r| {
        report::print_table(r);
        println!("wrote {}", dir.display());
    })
}
