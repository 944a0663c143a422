//! `photonmap tables`: every table and figure of the paper this machine can
//! regenerate, beside the paper's own numbers, into results/<renderer>/.
//! The renders behind Table 1, section 3.3 and figure 8 are in `renders`,
//! Table 2's instruction counts in `kernels`, the Markdown and CSV in
//! `markdown`; here are the command, its report, and the run that stages
//! every file and writes them all or nothing.

mod kernels;
mod markdown;
mod renders;

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;

use photonmap::bench::build::{bench_size, paper_grid, BuildBenchRow};
use photonmap::gpu::{Gpu, Platform};
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::render::{EstimateMode, Image, Method, PhotonMapOptions, RenderOptions};
use photonmap::scene::Scene;

use super::output::BenchOutput;
use renders::montage;

/// Reproduce the paper's tables and figures into results/<renderer>/ (or --out).
#[derive(Args)]
pub struct TablesArgs {
    /// Output folder (default: results/<renderer>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A reduced run for CI: quarter resolution, one run, fewer sizes and modes.
    #[arg(long)]
    pub quick: bool,
    /// The paper's 2003 constraints: a random-number texture, read-back
    /// before routing, float addressing, no compaction, the faithful sort
    /// passes, no projection maps, and stencil routing's m = 16.
    #[arg(long)]
    pub faithful: bool,
    /// Stencil routing's m, each cell holding m x m photons (1..=16; default
    /// 4, or 16 with --faithful).
    #[arg(long, value_name = "M", value_parser = crate::cli::args::in_range(1, 16))]
    pub stencil_m: Option<u32>,
    /// Table 1 and figure 7 only (no section 3.3, pass counts, figure 8 or
    /// Table 2).
    #[arg(long)]
    pub table1_only: bool,
    /// Runs per Table 1 cell, median and spread quoted (1..=20).
    #[arg(long, default_value_t = 3, value_parser = crate::cli::args::in_range(1, 20))]
    pub runs: u32,
    #[command(flatten)]
    pub output: BenchOutput,
}

pub fn run(a: &TablesArgs, platform: Platform) -> Result<()> {
    let gpu = crate::cli::gpu(platform)?;
    let (report, dir) = run_tables(&gpu, a, &a.output.progress())?;
    a.output.print(&report, |r| {
        print!("{}", markdown::document(r));
        eprintln!("wrote {}", dir.display());
    })
}

/// Table 1 of the paper (GeForce FX 5900 Ultra, seconds).
const PAPER_TABLE1: [(&str, [f64; 4], [f64; 4]); 3] = [
    ("glass_ball", [1.2, 0.8, 0.5, 14.9], [1.2, 1.8, 0.5, 7.8]),
    ("ring", [1.3, 0.8, 0.4, 6.5], [1.3, 1.8, 0.4, 4.6]),
    ("cornell_box", [2.1, 1.4, 8.4, 52.4], [2.1, 1.7, 8.4, 35.0]),
];
/// Steps per pixel per pass of figure 8's render.
const FIGURE8_BUDGET: u32 = 16;

const STAGES: [&str; 4] = [
    "trace photons",
    "build map",
    "trace rays",
    "radiance estimate",
];

#[derive(Serialize)]
pub struct Table1Cell {
    pub scene: String,
    pub build: BuildMethod,
    pub stage: String,
    pub wall_seconds: Vec<f64>,
    pub median_wall_seconds: f64,
    pub min_wall_seconds: f64,
    pub max_wall_seconds: f64,
    pub median_gpu_seconds: f64,
    pub paper_seconds: f64,
    pub ratio_to_paper: f64,
    pub at_or_below_paper: bool,
}

#[derive(Serialize)]
pub struct Table1Total {
    pub scene: String,
    pub build: BuildMethod,
    pub median_seconds: f64,
    pub paper_seconds: f64,
    pub ratio_to_paper: f64,
    /// The target: at most a quarter of the paper's total.
    pub at_most_a_quarter: bool,
}

#[derive(Serialize)]
pub struct ConvergenceRow {
    pub scene: String,
    pub mode: String,
    pub wall_seconds: f64,
    pub passes: u32,
    pub tile_draws: u64,
}

#[derive(Serialize)]
pub struct Figure8 {
    pub file: String,
    pub snapshots: Vec<(String, f64, f64)>,
    pub full_convergence_seconds: f64,
    pub visual_convergence_seconds: f64,
    pub criterion: String,
}

#[derive(Serialize)]
pub struct KernelCount {
    pub kernel: String,
    pub instructions: usize,
    pub texture_fetches: usize,
    pub address_arithmetic: usize,
    pub packing: usize,
    pub paper: [usize; 4],
}

#[derive(Serialize)]
pub struct TablesReport {
    pub renderer: String,
    pub gl_version: String,
    pub cores: usize,
    pub quick: bool,
    pub faithful: bool,
    pub stencil_m: u32,
    pub table1_only: bool,
    pub image_scale: String,
    pub runs: u32,
    pub command: String,
    pub table1: Vec<Table1Cell>,
    pub totals: Vec<Table1Total>,
    pub convergence: Vec<ConvergenceRow>,
    pub passes: Vec<BuildBenchRow>,
    pub figure7: String,
    pub figure8: Option<Figure8>,
    pub table2: Result<Vec<KernelCount>, String>,
}

fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        0.0
    } else if s.len() % 2 == 1 {
        s[s.len() / 2]
    } else {
        0.5 * (s[s.len() / 2 - 1] + s[s.len() / 2])
    }
}

/// photonmap-out/tables/<first word of the renderer, lower case>/: the
/// committed results/ change only when named with --out.
pub fn default_out(renderer: &str) -> PathBuf {
    let word: String = renderer
        .split_whitespace()
        .next()
        .unwrap_or("unknown")
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
        .collect::<String>()
        .to_lowercase();
    crate::cli::out_dir("tables").join(if word.is_empty() {
        "unknown".into()
    } else {
        word
    })
}

pub(crate) fn table1_options(
    scene: &Scene,
    scale: u32,
    build: BuildMethod,
    (faithful, stencil_m): (bool, u32),
    mode: EstimateMode,
) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    o.width = (scene.camera.width / scale).max(1);
    o.height = (scene.camera.height / scale).max(1);
    let mut gi = PhotonMapOptions {
        photons: PhotonConfig {
            build,
            faithful,
            stencil_block: stencil_m,
            // The paper aims no photons: it emits them all from the light.
            projection_maps: !faithful,
            ..PhotonConfig::default()
        },
        ..PhotonMapOptions::default()
    };
    gi.estimate.mode = mode;
    // The paper's estimate, every photon in the sphere, so the times compare
    // with the paper's (the default leak test costs RING about half again).
    gi.estimate.leak = photonmap::render::radiance_estimate::LeakTest::None;
    o.with_method(Method::PhotonMap(gi))
}

/// Every file of a `tables` run, kept until the run has finished and then
/// written all or nothing, so an interrupted or failed run leaves the
/// previous results as they were.
#[derive(Default)]
struct Staged(std::cell::RefCell<Vec<(PathBuf, Vec<u8>)>>);

impl Staged {
    fn add(&self, path: PathBuf, bytes: Vec<u8>) {
        self.0.borrow_mut().push((path, bytes));
    }

    fn png(&self, path: PathBuf, img: &Image) -> Result<()> {
        self.add(path, img.png_bytes()?);
        Ok(())
    }

    /// Writes every file; then removes older snapshots in `figure8/` that this run did not make.
    fn publish(self, out: &Path) -> Result<()> {
        let files = self.0.into_inner();
        let refs: Vec<(&Path, &[u8])> = files
            .iter()
            .map(|(p, b)| (p.as_path(), b.as_slice()))
            .collect();
        photonmap::image::write_all_atomically(&refs)?;
        let made: std::collections::HashSet<&Path> = refs.iter().map(|(p, _)| *p).collect();
        if let Ok(entries) = std::fs::read_dir(out.join("figure8")) {
            for e in entries.flatten() {
                if !made.contains(e.path().as_path()) {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        Ok(())
    }
}

pub fn run_tables(
    gpu: &Gpu,
    o: &TablesArgs,
    progress: &dyn Fn(&str),
) -> Result<(TablesReport, PathBuf)> {
    let caps = gpu.capabilities();
    let out = o
        .out
        .clone()
        .unwrap_or_else(|| default_out(&caps.gl_renderer));
    if o.table1_only && o.out.is_none() {
        anyhow::bail!(
            "--table1-only needs --out: Table 1 alone would replace the full run's tables.md in {}",
            out.display()
        );
    }
    let dirs: &[&str] = if o.table1_only {
        &["figure7"]
    } else {
        &["figure7", "figure8"]
    };
    for dir in dirs {
        std::fs::create_dir_all(out.join(dir))
            .with_context(|| format!("creating {}", out.display()))?;
    }
    let stencil_m = o.stencil_m.unwrap_or(if o.faithful { 16 } else { 4 });
    let run = TablesRun {
        gpu,
        scale: if o.quick { 4 } else { 1 },
        runs: if o.quick { 1 } else { o.runs },
        quick: o.quick,
        faithful: o.faithful,
        stencil_m,
        out: &out,
        progress,
        staged: Staged::default(),
    };
    let (table1, totals, figure7_rows) = run.table1()?;
    run.staged
        .png(out.join("figure7.png"), &montage(&figure7_rows))?;
    let (mut convergence, mut passes, mut figure8) = (Vec::new(), Vec::new(), None);
    if !o.table1_only {
        convergence = run.section_3_3()?;
        for k in 10..=(if o.quick { 12 } else { 20 }) {
            progress(&format!("Passes: n = 2^{k}"));
            passes.push(bench_size(gpu, 1 << k, &paper_grid(), stencil_m)?);
        }
        figure8 = Some(run.figure8()?);
        progress("Table 2: SPIR-V instruction counts");
    }
    let report = TablesReport {
        renderer: caps.gl_renderer,
        gl_version: caps.gl_version,
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        quick: o.quick,
        faithful: o.faithful,
        stencil_m,
        table1_only: o.table1_only,
        image_scale: if o.quick {
            "1/4 of the paper's resolution".into()
        } else {
            "the paper's resolution".into()
        },
        runs: run.runs,
        command: format!(
            "photonmap tables{}{}{}{}",
            if o.quick { " --quick" } else { "" },
            if o.faithful { " --faithful" } else { "" },
            o.stencil_m
                .map_or(String::new(), |m| format!(" --stencil-m {m}")),
            if o.table1_only { " --table1-only" } else { "" }
        ),
        table1,
        totals,
        convergence,
        passes,
        figure7: "figure7.png".into(),
        figure8,
        table2: if o.table1_only {
            Err("not run (--table1-only)".into())
        } else {
            kernels::table2()
        },
    };
    let staged = run.staged;
    staged.add(
        out.join("results.json"),
        serde_json::to_string_pretty(&report)?.into_bytes(),
    );
    staged.add(
        out.join("table1.csv"),
        markdown::table1_csv(&report).into_bytes(),
    );
    staged.add(
        out.join("tables.md"),
        markdown::document(&report).into_bytes(),
    );
    staged.publish(&out)?;
    Ok((report, out))
}

/// One `tables` run: its scale, runs per cell and output folder.
struct TablesRun<'a> {
    gpu: &'a Gpu,
    scale: u32,
    runs: u32,
    quick: bool,
    faithful: bool,
    stencil_m: u32,
    out: &'a Path,
    progress: &'a dyn Fn(&str),
    staged: Staged,
}

type Table1 = (Vec<Table1Cell>, Vec<Table1Total>, Vec<Vec<Image>>);
