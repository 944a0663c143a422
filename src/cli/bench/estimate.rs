//! `photonmap bench estimate`: where the kNN-grid radiance estimate's time
//! goes, and what each speed-up buys. Each scene renders at Table 1's
//! settings (`tables`: the paper's resolution and estimate, bitonic build,
//! 16 x 16 tiles) once per variant of the search; every variant must give the
//! paper search's image bit for bit, and the bench fails if one does not.
//! Per variant: the estimate's wall time (median of --runs), passes, tile
//! draws, and the per-pixel counters of glsl/render/knn_search.frag (steps,
//! photons examined, cells opened) summed; then one more, profiled run reads
//! the state back after every pass for lane use (divergence), whose time is
//! not quoted.

use anyhow::{bail, Result};
use clap::Args;
use serde::Serialize;

use photonmap::gpu::{Gpu, Platform};
use photonmap::photon::BuildMethod;
use photonmap::render::search_work::SearchWork;
use photonmap::render::{render, EstimateMode, Image};
use photonmap::scene::{embedded, Scene};

use super::output::BenchOutput;

#[derive(Args)]
pub struct EstimateBenchArgs {
    /// Scenes (files or embedded names; default the paper's three).
    #[arg(long, num_args = 1.., default_values_t = ["glass_ball".to_string(), "ring".into(), "cornell_box".into()])]
    pub scene: Vec<String>,
    /// Timed runs per variant, median quoted (1..=20).
    #[arg(long, default_value_t = 3, value_parser = crate::cli::args::in_range(1, 20))]
    pub runs: u32,
    /// Skip the profiled run (lane use).
    #[arg(long)]
    pub no_lanes: bool,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// A way of running the same search.
struct Variant {
    label: &'static str,
    what: &'static str,
    /// `EstimateOptions`' cull, runs and budget.
    search: (bool, bool, u32),
}

const VARIANTS: [Variant; 5] = [
    Variant {
        label: "paper",
        what: "every cell of every ring opened, one by one (the paper's search)",
        search: (false, false, 64),
    },
    Variant {
        label: "culled",
        what: "cells, rows and planes beyond the search radius skipped unopened",
        search: (true, false, 64),
    },
    Variant {
        label: "culled + runs",
        what: "and a face row's cells read as one range of photons (sorted map)",
        search: (true, true, 64),
    },
    Variant {
        label: "... 128 steps a pass (default)",
        what: "and 128 steps a pixel a pass, not 64: half the passes",
        search: (true, true, 128),
    },
    Variant {
        label: "... 256 steps a pass",
        what: "and 256 steps a pixel a pass: a quarter of the passes",
        search: (true, true, 256),
    },
];

#[derive(Serialize)]
pub struct Row {
    pub scene: String,
    pub variant: String,
    pub what: String,
    pub estimate_seconds: Vec<f64>,
    pub median_estimate_seconds: f64,
    /// The render's other stages (photons, map, rays), median run's.
    pub other_stages_seconds: f64,
    pub passes: u32,
    pub tile_draws: u64,
    pub query_pixels: u64,
    pub work: SearchWork,
    /// Per query pixel.
    pub steps_per_pixel: f64,
    pub photons_examined_per_pixel: f64,
    pub cells_opened_per_pixel: f64,
    /// Estimate time against the first variant's, in this run.
    pub speedup: f64,
    /// The image equals the first variant's bit for bit.
    pub identical: bool,
}

#[derive(Serialize)]
pub struct EstimateBench {
    pub renderer: String,
    pub command: String,
    pub rows: Vec<Row>,
}

pub fn run(a: &EstimateBenchArgs, platform: Platform) -> Result<()> {
    let gpu = crate::cli::gpu(platform)?;
    let say = a.output.progress();
    let mut rows = Vec::new();
    for name in &a.scene {
        let scene = embedded::load_path_or_name(std::path::Path::new(name))?;
        rows.extend(scene_rows(&gpu, &scene, a, &say)?);
    }
    let bench = EstimateBench {
        renderer: gpu.capabilities().gl_renderer,
        command: std::env::args().collect::<Vec<_>>().join(" "),
        rows,
    };
    a.output.print(&bench, print_table)?;
    if let Some(r) = bench.rows.iter().find(|r| !r.identical) {
        bail!(
            "{}: the {} search's image differs from the paper search's",
            r.scene,
            r.variant
        );
    }
    Ok(())
}

fn scene_rows(
    gpu: &Gpu,
    scene: &Scene,
    a: &EstimateBenchArgs,
    say: &dyn Fn(&str),
) -> Result<Vec<Row>> {
    let mut rows: Vec<Row> = Vec::new();
    let mut first: Option<(Image, f64)> = None;
    for v in &VARIANTS {
        let mut options = super::tables::table1_options(
            scene,
            1,
            BuildMethod::Bitonic,
            (false, 4),
            EstimateMode::Tiled { tile: 16 },
        );
        let gi = options
            .photon_map_mut()
            .expect("Table 1 renders global light");
        (gi.estimate.cull, gi.estimate.runs, gi.estimate.budget) = v.search;
        let mut times = Vec::new();
        let mut last = None;
        for run in 0..a.runs {
            say(&format!(
                "{}: {} search, run {}/{}",
                scene.name,
                v.label,
                run + 1,
                a.runs
            ));
            let out = render(gpu, scene, &options, &mut ())?;
            let stats = out.estimate().cloned().unwrap_or_default();
            let total: f64 = out.timings.stages.iter().map(|s| s.wall_seconds).sum();
            times.push((stats.wall_seconds, total - stats.wall_seconds));
            last = Some((out.image, stats));
        }
        let (image, mut stats) = last.expect("at least one run");
        if !a.no_lanes {
            say(&format!("{}: {} search, profiled run", scene.name, v.label));
            let gi = options
                .photon_map_mut()
                .expect("Table 1 renders global light");
            gi.estimate.profile_lanes = true;
            let out = render(gpu, scene, &options, &mut ())?;
            stats.work.lanes = out.estimate().and_then(|s| s.work.lanes.clone());
        }
        times.sort_by(|x, y| x.0.total_cmp(&y.0));
        let (median, others) = times[times.len() / 2];
        let (identical, speedup) = match &first {
            None => {
                first = Some((image.clone(), median));
                (true, 1.0)
            }
            Some((img, t)) => (img.pixels == image.pixels, t / median.max(1e-9)),
        };
        let per = |n: u64| n as f64 / stats.query_pixels.max(1) as f64;
        rows.push(Row {
            scene: scene.name.clone(),
            variant: v.label.into(),
            what: v.what.into(),
            estimate_seconds: times.iter().map(|t| t.0).collect(),
            median_estimate_seconds: median,
            other_stages_seconds: others,
            passes: stats.passes,
            tile_draws: stats.tile_draws,
            query_pixels: stats.query_pixels,
            steps_per_pixel: per(stats.work.steps),
            photons_examined_per_pixel: per(stats.work.photons_examined),
            cells_opened_per_pixel: per(stats.work.cells_opened),
            work: stats.work,
            speedup,
            identical,
        });
    }
    Ok(rows)
}

fn print_table(b: &EstimateBench) {
    println!("# The radiance estimate's work ({})\n", b.renderer);
    println!("`{}`\n", b.command);
    println!("| scene | search | estimate s | speed-up | passes | tile draws | steps / px | photons / px | cells / px | lane use 8 | lane use 32 | same image |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &b.rows {
        let lanes = |f: fn(&photonmap::render::search_work::LaneUse) -> f64| {
            r.work
                .lanes
                .as_ref()
                .map_or("-".to_string(), |l| format!("{:.2}", f(l)))
        };
        println!(
            "| {} | {} | {:.2} | {:.2} | {} | {} | {:.0} | {:.0} | {:.0} | {} | {} | {} |",
            r.scene,
            r.variant,
            r.median_estimate_seconds,
            r.speedup,
            r.passes,
            r.tile_draws,
            r.steps_per_pixel,
            r.photons_examined_per_pixel,
            r.cells_opened_per_pixel,
            lanes(|l| l.use_8_lanes),
            lanes(|l| l.use_32_lanes),
            if r.identical { "yes" } else { "NO" }
        );
    }
}
