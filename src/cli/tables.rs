//! `photonmap tables`: every table and figure of the paper this machine can
//! regenerate, beside the paper's own numbers, into results/<renderer>/.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;

use photonmap::gpu::{Gpu, Platform};
use photonmap::photon::bench::{bench_size, paper_grid, BuildBenchRow};
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::render::software::software_image;
use photonmap::render::{render, EstimateMode, Image, Method, PhotonMapOptions, RenderOptions};
use photonmap::scene::{embedded, Scene};

use super::render::{SnapshotEvery, SnapshotWriter};

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
    #[arg(long, value_name = "M", value_parser = super::args::in_range(1, 16))]
    pub stencil_m: Option<u32>,
    /// Table 1 and figure 7 only (no section 3.3, pass counts, figure 8 or
    /// Table 2).
    #[arg(long)]
    pub table1_only: bool,
    /// Runs per Table 1 cell, median and spread quoted (1..=20).
    #[arg(long, default_value_t = 3, value_parser = super::args::in_range(1, 20))]
    pub runs: u32,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(a: &TablesArgs, platform: Platform) -> Result<()> {
    let gpu = super::gpu(platform)?;
    let (report, dir) = run_tables(&gpu, a, &super::progress_lines(a.quiet))?;
    if a.json {
        super::print_json(&report)?;
    } else {
        print!("{}", markdown(&report));
        eprintln!("wrote {}", dir.display());
    }
    Ok(())
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
    super::out_dir("tables").join(if word.is_empty() {
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

fn stage_seconds(t: &photonmap::render::Timings, stage: &str) -> (f64, f64) {
    let names: &[&str] = match stage {
        "trace rays" => &["eye rays", "intersect", "shadow rays", "specular"],
        other => std::slice::from_ref(match other {
            "trace photons" => &"trace photons",
            "build map" => &"build map",
            _ => &"radiance estimate",
        }),
    };
    let pick = |f: fn(&photonmap::render::StageTiming) -> f64| {
        t.stages
            .iter()
            .filter(|s| names.contains(&s.name.as_str()))
            .map(f)
            .sum::<f64>()
    };
    (pick(|s| s.wall_seconds), pick(|s| s.gpu_seconds))
}

/// Places images side by side in rows (all of one row the same height).
fn montage(rows: &[Vec<Image>]) -> Image {
    let width = rows
        .iter()
        .map(|r| r.iter().map(|i| i.width).sum::<u32>())
        .max()
        .unwrap_or(1);
    let height = rows
        .iter()
        .map(|r| r.iter().map(|i| i.height).max().unwrap_or(0))
        .sum::<u32>();
    let mut out = Image::new(width, height.max(1));
    let mut y0 = 0;
    for row in rows {
        let mut x0 = 0;
        for img in row {
            for y in 0..img.height {
                for x in 0..img.width {
                    out.pixels[((y0 + y) * width + x0 + x) as usize] = img.get(x, y);
                }
            }
            x0 += img.width;
        }
        y0 += row.iter().map(|i| i.height).max().unwrap_or(0);
    }
    out
}

fn crop(img: &Image, x0: u32, y0: u32, w: u32, h: u32) -> Image {
    let mut out = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            out.pixels[(y * w + x) as usize] = img.get(x0 + x, y0 + y);
        }
    }
    out
}

fn read_png(path: &Path) -> Result<Image> {
    let img = image::open(path)
        .with_context(|| format!("reading {}", path.display()))?
        .to_rgb8();
    let (w, h) = img.dimensions();
    // Kept as 8-bit sRGB values over 255: only compared with other PNGs.
    let pixels = img
        .pixels()
        .map(|p| {
            [
                p[0] as f32 / 255.0,
                p[1] as f32 / 255.0,
                p[2] as f32 / 255.0,
            ]
        })
        .collect();
    Ok(Image {
        width: w,
        height: h,
        pixels,
    })
}

/// Fraction of pixels whose 8-bit sRGB value differs from the final image's by
/// more than 2 levels in any channel.
fn visibly_different(a: &Image, b: &Image) -> f64 {
    let n = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > 2.5 / 255.0))
        .count();
    n as f64 / a.pixels.len().max(1) as f64
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

/// Counts the instructions of a kernel's optimised SPIR-V (glslangValidator -Os).
fn spirv_counts(
    vertex: Option<&str>,
    fragment: &str,
    defines: &[(&str, String)],
) -> Result<(usize, usize, usize), String> {
    let dir = std::env::temp_dir().join(format!("photonmap-spirv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let mut totals = (0, 0, 0);
    for (stage, name) in vertex
        .map(|v| ("vert", v))
        .into_iter()
        .chain([("frag", fragment)])
    {
        let src = photonmap::gpu::program::preprocessed_source(name, defines)
            .ok_or("missing GLSL file")?;
        let path = dir.join(format!("kernel.{stage}"));
        std::fs::write(&path, src).map_err(|e| e.to_string())?;
        let out = std::process::Command::new("glslangValidator")
            .args(["-G", "--aml", "--amb", "-Os", "-H", "-S", stage])
            .arg(&path)
            .arg("-o")
            .arg(dir.join("kernel.spv"))
            .output()
            .map_err(|_| {
                "glslangValidator is not installed (apt-get install glslang-tools)".to_string()
            })?;
        if !out.status.success() {
            return Err(format!(
                "glslangValidator failed on glsl/{name}: {}",
                String::from_utf8_lossy(&out.stdout)
                    .lines()
                    .last()
                    .unwrap_or("")
            ));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let mut in_function = false;
        for line in text.lines() {
            let op = line
                .split_whitespace()
                .find(|w| w.chars().next().is_some_and(|c| c.is_ascii_uppercase()))
                .unwrap_or("");
            if op == "Function" {
                in_function = true;
                continue;
            }
            if op == "FunctionEnd" {
                in_function = false;
            }
            if !in_function
                || matches!(
                    op,
                    "" | "Label"
                        | "SelectionMerge"
                        | "LoopMerge"
                        | "Variable"
                        | "Phi"
                        | "FunctionParameter"
                )
            {
                continue;
            }
            totals.0 += 1;
            totals.1 += usize::from(
                op.starts_with("ImageFetch") || op.starts_with("ImageSample") || op == "ImageRead",
            );
            let integer_op = matches!(
                op,
                "IAdd"
                    | "ISub"
                    | "IMul"
                    | "SDiv"
                    | "UDiv"
                    | "SMod"
                    | "SRem"
                    | "UMod"
                    | "BitwiseAnd"
                    | "BitwiseOr"
                    | "BitwiseXor"
                    | "ShiftLeftLogical"
                    | "ShiftRightLogical"
                    | "ShiftRightArithmetic"
                    | "ConvertFToS"
                    | "ConvertSToF"
            );
            totals.2 += usize::from(integer_op);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(totals)
}

fn table2() -> Result<Vec<KernelCount>, String> {
    let routed = vec![("ROUTED", "1".to_string())];
    // (name, vertex program, fragment program, defines, the paper's counts)
    type Kernel<'a> = (
        &'a str,
        Option<&'a str>,
        &'a str,
        Vec<(&'a str, String)>,
        [usize; 4],
    );
    let kernels: [Kernel; 5] = [
        (
            "Bitonic Sort",
            None,
            "photon/bitonic.frag",
            vec![],
            [52, 2, 13, 0],
        ),
        (
            "Binary Search",
            None,
            "photon/binary_search.frag",
            vec![],
            [18, 1, 13, 0],
        ),
        (
            "Rad. Estimate (sorted map)",
            None,
            "render/knn_search.frag",
            vec![],
            [202, 6, 47, 41],
        ),
        (
            "Stencil Routing",
            Some("photon/route.vert"),
            "photon/route.frag",
            vec![],
            [42, 0, 25, 0],
        ),
        (
            "Rad. Estimate (routed map)",
            None,
            "render/knn_search.frag",
            routed,
            [193, 5, 20, 41],
        ),
    ];
    kernels
        .into_iter()
        .map(|(kernel, vertex, fragment, defines, paper)| {
            let (instructions, texture_fetches, address_arithmetic) =
                spirv_counts(vertex, fragment, &defines)?;
            Ok(KernelCount {
                kernel: kernel.into(),
                instructions,
                texture_fetches,
                address_arithmetic,
                packing: 0,
                paper,
            })
        })
        .collect()
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
            table2()
        },
    };
    let staged = run.staged;
    staged.add(
        out.join("results.json"),
        serde_json::to_string_pretty(&report)?.into_bytes(),
    );
    staged.add(out.join("table1.csv"), table1_csv(&report).into_bytes());
    staged.add(out.join("tables.md"), markdown(&report).into_bytes());
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

impl TablesRun<'_> {
    fn table1_options(
        &self,
        scene: &Scene,
        build: BuildMethod,
        mode: EstimateMode,
    ) -> RenderOptions {
        table1_options(
            scene,
            self.scale,
            build,
            (self.faithful, self.stencil_m),
            mode,
        )
    }

    /// Table 1 (and figure 7's images from the first run of each).
    fn table1(&self) -> Result<Table1> {
        let (mut table1, mut totals, mut figure7_rows) = (Vec::new(), Vec::new(), Vec::new());
        for (name, paper_bitonic, paper_stencil) in PAPER_TABLE1 {
            let scene = embedded::load(name)?;
            let mut row = Vec::new();
            for (build, paper) in [
                (BuildMethod::Bitonic, paper_bitonic),
                (BuildMethod::Stencil, paper_stencil),
            ] {
                let (cells, total) = self.table1_cell(name, &scene, build, paper, &mut row)?;
                table1.extend(cells);
                totals.push(total);
            }
            // Row order as in figure 7: bitonic, stencil, software.
            row.swap(1, 2);
            figure7_rows.push(row);
        }
        Ok((table1, totals, figure7_rows))
    }

    /// One scene and build of Table 1: every stage over the runs, and the total.
    fn table1_cell(
        &self,
        name: &str,
        scene: &Scene,
        build: BuildMethod,
        paper: [f64; 4],
        row: &mut Vec<Image>,
    ) -> Result<(Vec<Table1Cell>, Table1Total)> {
        let runs = self.runs;
        let mut walls = vec![Vec::new(); 4];
        let mut gpus = vec![Vec::new(); 4];
        let mut run_totals = Vec::new();
        for run in 0..runs {
            (self.progress)(&format!("Table 1: {name} {build:?} run {}/{runs}", run + 1));
            let opts = self.table1_options(scene, build, EstimateMode::Tiled { tile: 16 });
            let r = render(self.gpu, scene, &opts, &mut ())?;
            let mut total = 0.0;
            for (i, stage) in STAGES.iter().enumerate() {
                let (w, g) = stage_seconds(&r.timings, stage);
                walls[i].push(w);
                gpus[i].push(g);
                total += w;
            }
            run_totals.push(total);
            if run == 0 {
                let file = self
                    .out
                    .join("figure7")
                    .join(format!("{name}_{build:?}.png").to_lowercase());
                self.staged.png(file, &r.image)?;
                row.push(r.image.clone());
                if build == BuildMethod::Bitonic {
                    (self.progress)(&format!("Figure 7: {name} software reference"));
                    let sw = software_image(&r, scene).context("software reference")?;
                    let file = self
                        .out
                        .join("figure7")
                        .join(format!("{name}_software.png"));
                    self.staged.png(file, &sw)?;
                    row.push(sw);
                }
            }
        }
        let cells = STAGES
            .iter()
            .enumerate()
            .map(|(i, stage)| {
                let med = median(&walls[i]);
                Table1Cell {
                    scene: scene.name.clone(),
                    build,
                    stage: stage.to_string(),
                    median_wall_seconds: med,
                    min_wall_seconds: walls[i].iter().copied().fold(f64::INFINITY, f64::min),
                    max_wall_seconds: walls[i].iter().copied().fold(0.0, f64::max),
                    median_gpu_seconds: median(&gpus[i]),
                    wall_seconds: walls[i].clone(),
                    paper_seconds: paper[i],
                    ratio_to_paper: med / paper[i],
                    at_or_below_paper: med <= paper[i],
                }
            })
            .collect();
        let paper_total: f64 = paper.iter().sum();
        let med = median(&run_totals);
        let total = Table1Total {
            scene: scene.name.clone(),
            build,
            median_seconds: med,
            paper_seconds: paper_total,
            ratio_to_paper: med / paper_total,
            at_most_a_quarter: med <= paper_total / 4.0,
        };
        Ok((cells, total))
    }

    /// Section 3.3: full convergence of the estimate by drawing mode.
    fn section_3_3(&self) -> Result<Vec<ConvergenceRow>> {
        let mut convergence = Vec::new();
        let mut modes: Vec<(String, EstimateMode)> =
            vec![("full screen".into(), EstimateMode::FullScreen)];
        let tiles: &[u32] = if self.quick { &[16] } else { &[8, 16, 32, 64] };
        for &t in tiles {
            modes.push((format!("{t} x {t} tiles"), EstimateMode::Tiled { tile: t }));
        }
        modes.push(("mask every pass".into(), EstimateMode::Masked { every: 1 }));
        for name in ["glass_ball", "cornell_box"] {
            let scene = embedded::load(name)?;
            for (label, mode) in &modes {
                (self.progress)(&format!("Section 3.3: {name} {label}"));
                let opts = self.table1_options(&scene, BuildMethod::Bitonic, *mode);
                let r = render(self.gpu, &scene, &opts, &mut ())?;
                let e = r.estimate().cloned().unwrap_or_default();
                convergence.push(ConvergenceRow {
                    scene: scene.name.clone(),
                    mode: label.clone(),
                    wall_seconds: stage_seconds(&r.timings, "radiance estimate").0,
                    passes: e.passes,
                    tile_draws: e.tile_draws,
                });
            }
        }
        Ok(convergence)
    }

    /// Figure 8: the GLASS BALL caustic during convergence.
    fn figure8(&self) -> Result<Figure8> {
        (self.progress)("Figure 8: GLASS BALL snapshots");
        // Snapshots are written to a temporary folder and staged from there.
        let temporary = tempfile::tempdir()?;
        let snap_dir = temporary.path().to_path_buf();
        let scene = embedded::load("glass_ball")?;
        let mut opts = self.table1_options(
            &scene,
            BuildMethod::Bitonic,
            EstimateMode::Tiled { tile: 16 },
        );
        // Finer passes than the default's, so that the snapshots show the
        // estimate converging rather than four or five jumps (the same image).
        if let Some(gi) = opts.photon_map_mut() {
            gi.estimate.budget = FIGURE8_BUDGET;
        }
        let mut writer = SnapshotWriter::new(snap_dir.clone(), SnapshotEvery::Passes(1));
        render(self.gpu, &scene, &opts, &mut writer)?;
        let written = writer.written;
        let final_img = read_png(&snap_dir.join(&written.last().context("no snapshots")?.file))?;
        let mut snaps = Vec::new();
        for s in &written {
            let img = read_png(&snap_dir.join(&s.file))?;
            snaps.push((
                s.file.clone(),
                s.seconds,
                visibly_different(&img, &final_img),
            ));
        }
        let full = written.last().map_or(0.0, |s| s.seconds);
        // Visually converged: from here on, under 1% of pixels visibly differ from the final image.
        let mut visual = full;
        for i in (0..snaps.len()).rev() {
            if snaps[i].2 < 0.01 {
                visual = snaps[i].1;
            } else {
                break;
            }
        }
        let picks: Vec<usize> = [0.1, 0.25, 0.5]
            .iter()
            .map(|f| snaps.iter().position(|s| s.1 >= f * full).unwrap_or(0))
            .chain([snaps.len() - 1])
            .collect();
        let (w, h) = (final_img.width, final_img.height);
        let crops: Vec<Image> = picks
            .iter()
            .map(|&i| {
                read_png(&snap_dir.join(&snaps[i].0)).map(|im| {
                    // Back to linear so png_bytes' sRGB encoding reproduces the snapshot values.
                    let mut c = crop(&im, w * 3 / 10, h / 2, w * 2 / 5, h * 7 / 20);
                    for p in &mut c.pixels {
                        for v in p.iter_mut() {
                            *v = srgb_to_linear(*v);
                        }
                    }
                    c
                })
            })
            .collect::<Result<_>>()?;
        let index = std::iter::once("snapshots.json".to_string());
        for file in written.iter().map(|s| s.file.clone()).chain(index) {
            let bytes = std::fs::read(snap_dir.join(&file))?;
            self.staged.add(self.out.join("figure8").join(&file), bytes);
        }
        self.staged
            .png(self.out.join("figure8.png"), &montage(&[crops]))?;
        Ok(Figure8 {
            file: "figure8.png".into(),
            snapshots: picks.iter().map(|&i| snaps[i].clone()).collect(),
            full_convergence_seconds: full,
            visual_convergence_seconds: visual,
            criterion: "every later snapshot has under 1% of pixels differing from the final image by more than 2 of 255 sRGB levels".into(),
        })
    }
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn table1_csv(r: &TablesReport) -> String {
    let mut s = String::from(
        "scene,build,stage,median_wall_s,min_wall_s,max_wall_s,median_gpu_s,paper_s,ratio\n",
    );
    for c in &r.table1 {
        s += &format!(
            "{},{:?},{},{:.4},{:.4},{:.4},{:.4},{},{:.4}\n",
            c.scene,
            c.build,
            c.stage,
            c.median_wall_seconds,
            c.min_wall_seconds,
            c.max_wall_seconds,
            c.median_gpu_seconds,
            c.paper_seconds,
            c.ratio_to_paper
        );
    }
    s
}

pub fn markdown(r: &TablesReport) -> String {
    let mut s = format!(
        "# The paper's tables on {}\n\n`{}`: {} ({} cores), {}, {} run{} a cell (median; min..max).\nPaper figures: GeForce FX 5900 Ultra (2003), in brackets. Times are wall clock with glFinish at each stage's ends.\n\n",
        r.renderer,
        r.command,
        r.gl_version,
        r.cores,
        r.image_scale,
        r.runs,
        if r.runs == 1 { "" } else { "s" }
    );
    s += "## Table 1: seconds per stage\n\n| scene | build | trace photons | build map | trace rays | radiance estimate | total | total / paper |\n|---|---|---|---|---|---|---|---|\n";
    for t in &r.totals {
        let cells: Vec<String> = STAGES
            .iter()
            .map(|st| {
                let c = r
                    .table1
                    .iter()
                    .find(|c| c.scene == t.scene && c.build == t.build && c.stage == *st)
                    .expect("cell");
                let mark = if c.at_or_below_paper { "" } else { " ▲" };
                format!(
                    "{:.2} ({}){mark} <br>{:.2}..{:.2}",
                    c.median_wall_seconds, c.paper_seconds, c.min_wall_seconds, c.max_wall_seconds
                )
            })
            .collect();
        s += &format!(
            "| {} | {:?} | {} | {:.2} ({:.1}) | {:.2}{} |\n",
            t.scene,
            t.build,
            cells.join(" | "),
            t.median_seconds,
            t.paper_seconds,
            t.ratio_to_paper,
            if t.at_most_a_quarter { "" } else { " ▲" }
        );
    }
    s +=
        "\n▲ marks a cell above the paper's figure, or a total above a quarter of the paper's.\n\n";
    s += &format!(
        "Stencil routing: m = {}{}.\n\n",
        r.stencil_m,
        if r.faithful {
            "; the paper's 2003 constraints (--faithful): a random-number texture, read-back before routing, float addressing, no compaction, the faithful sort passes, no projection maps"
        } else {
            ""
        }
    );
    if r.table1_only {
        s += "## Figure 7: bitonic, stencil routing, software (kd-tree), per scene\n\n![figure 7](figure7.png)\n";
        return s;
    }
    s += "## Section 3.3: full convergence of the radiance estimate by drawing mode (seconds)\n\nPaper: CORNELL BOX 104 s full screen, 52.4 s with 16 x 16 tiles; GLASS BALL 102 s and 14.9 s.\n\n| scene | mode | seconds | passes | tile draws |\n|---|---|---|---|---|\n";
    for c in &r.convergence {
        s += &format!(
            "| {} | {} | {:.2} | {} | {} |\n",
            c.scene, c.mode, c.wall_seconds, c.passes, c.tile_draws
        );
    }
    s += "\n## Bitonic passes against n (paper: 210 passes for 1024 x 1024)\n\n| photons | passes | sort ms | ms a pass | copy pass ms | pass / copy | binary search ms | stencil routing ms | with read-back ms |\n|---|---|---|---|---|---|---|---|---|\n";
    for p in &r.passes {
        s += &format!(
            "| {} | {} | {:.2} | {:.3} | {:.3} | {:.2} | {:.3} | {:.2} | {:.2} |\n",
            p.photons,
            p.bitonic_passes,
            p.bitonic_sort_seconds * 1e3,
            p.bitonic_seconds_per_pass * 1e3,
            p.copy_pass_seconds * 1e3,
            p.pass_to_copy_ratio,
            p.binary_search_seconds * 1e3,
            p.stencil_vertex_fetch_seconds * 1e3,
            p.stencil_readback_seconds * 1e3
        );
    }
    s += "\n## Figure 7: bitonic, stencil routing, software (kd-tree), per scene\n\n![figure 7](figure7.png)\n\n";
    let Some(figure8) = &r.figure8 else {
        return s;
    };
    s += &format!(
        "## Figure 8: the GLASS BALL caustic during convergence\n\n![figure 8](figure8.png)\n\nDrawn {} steps a pass. Snapshots at {} s (the last is the final image). Full convergence {:.2} s; visually converged at {:.2} s ({}). Paper: about 4 s of 14.9 s.\n\n",
        FIGURE8_BUDGET,
        figure8.snapshots.iter().map(|s| format!("{:.2}", s.1)).collect::<Vec<_>>().join(", "),
        figure8.full_convergence_seconds,
        figure8.visual_convergence_seconds,
        figure8.criterion
    );
    s += "## Table 2 analogue: instructions per kernel\n\nStatic counts of the whole kernel (a loop body once) in SPIR-V from `glslangValidator -G -Os`, not the driver's own code; *Addr* counts integer and conversion operations; *Pack* is 0 because every output has its own render target. The paper's Cg counts (one iteration) in brackets.\n\n";
    match &r.table2 {
        Ok(rows) => {
            s += "| kernel | instructions | texture fetches | address arithmetic | packing |\n|---|---|---|---|---|\n";
            for k in rows {
                s += &format!(
                    "| {} | {} ({}) | {} ({}) | {} ({}) | {} ({}) |\n",
                    k.kernel,
                    k.instructions,
                    k.paper[0],
                    k.texture_fetches,
                    k.paper[1],
                    k.address_arithmetic,
                    k.paper[2],
                    k.packing,
                    k.paper[3]
                );
            }
        }
        Err(e) => s += &format!("Not measured: {e}.\n"),
    }
    s
}
