//! `photonmap bench`: benchmarks and the stress suite, commands rather than
//! tests, each with `--json` so anyone can rerun them.

use anyhow::{bail, Result};
use clap::{Args, Subcommand};

use photonmap::gpu::{Gpu, Platform};
use photonmap::photon::bench::{bench_mask, bench_size, paper_grid, BuildBenchRow};
use photonmap::stress::Outcome;

use super::args::in_range;

#[derive(Subcommand)]
pub enum BenchCommand {
    /// The stress suite: scale and place, sizes, crowding, grids, search edges,
    /// difficult paths, the furnace; one JSON object per case with --json.
    Stress(StressArgs),
    /// Run time against error around a scene's defaults (photons, k, maximum
    /// radius, shadow rays, build, tiling, samples) and SPPM, against its SPPM
    /// reference; CSV, JSON, SVG and PNG plots of the Pareto front.
    Accuracy(super::accuracy::AccuracyArgs),
    /// The BVH at scale: a ball on a floor, analytic and as meshes of growing
    /// size; BVH build, eye/shadow/photon rays per second, render times.
    Meshes(super::meshes::MeshesArgs),
    /// Instant global illumination with Marques and Santos's accelerations
    /// one at a time, and their remedies: time by component (their figures 4
    /// and 5) and error against the SPPM reference.
    Igi(super::igi_bench::IgiBenchArgs),
    /// Photon differentials against the kNN-grid at the same photons: time
    /// and error, the BVH's leaf size (their Table 1), and k_PM ~ k_PD.
    Differentials(super::differentials_bench::DifferentialsBenchArgs),
    /// photonmap at a scene's defaults against Mitsuba 3 (path and light
    /// tracing) at the same wall time, both against the SPPM reference; runs
    /// Mitsuba through --python (not a dependency).
    Mitsuba(super::mitsuba_bench::MitsubaBenchArgs),
    /// Whether the stencil test skips fragment work on this driver (the
    /// computation mask): an expensive pass with 0%, 50% and 90% of pixels masked.
    Mask(MaskArgs),
    /// Photon-map builds for n = 2^min .. 2^max synthetic photons: bitonic passes,
    /// time per pass against a copy pass, binary search, stencil routing with and
    /// without read-back.
    Build(BuildArgs),
    /// Where the kNN-grid radiance estimate's time goes (steps, photons
    /// examined, cells opened, passes, lane use) for each variant of the
    /// search, each checked to give the paper search's image bit for bit.
    Estimate(super::estimate_bench::EstimateBenchArgs),
}

#[derive(Args)]
pub struct StressArgs {
    /// Only the cases that take seconds.
    #[arg(long)]
    pub quick: bool,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Args)]
pub struct MaskArgs {
    /// Side of the square pass in pixels (16..=8192).
    #[arg(long, default_value_t = 512, value_parser = in_range(16, 8192))]
    pub size: u32,
    /// Rounds of sin/cos per pixel (1..=100000).
    #[arg(long, default_value_t = 200, value_parser = in_range(1, 100_000))]
    pub iterations: u32,
    #[arg(long)]
    pub json: bool,
}

#[derive(Args)]
pub struct BuildArgs {
    /// Smallest size, 2^min photons (1..=24).
    #[arg(long, default_value_t = 10, value_parser = in_range(1, 24))]
    pub min_log2: u32,
    /// Largest size, 2^max photons (min..=24).
    #[arg(long, default_value_t = 20, value_parser = in_range(1, 24))]
    pub max_log2: u32,
    /// Stencil routing m (the paper: a 1024 x 1024 buffer of about 40^3 cells; 1..=16).
    #[arg(long, default_value_t = 4, value_parser = in_range(1, 16))]
    pub stencil_m: u32,
    /// The grid's storage: uniform, or a hash table (section 4.4).
    #[arg(long, value_enum, default_value_t = photonmap::photon::GridKind::Uniform)]
    pub grid: photonmap::photon::GridKind,
    /// Hash buckets of `--grid hash` (1..=16777216; default: the next power of two >= the photons).
    #[arg(long, value_name = "N", value_parser = in_range(1, photonmap::photon::build::MAX_HASH_BUCKETS))]
    pub hash_buckets: Option<u32>,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

pub fn run(command: BenchCommand, platform: Platform) -> Result<()> {
    match command {
        BenchCommand::Stress(a) => run_stress(&a, platform),
        BenchCommand::Accuracy(a) => super::accuracy::run_bench(&a, platform),
        BenchCommand::Mask(a) => run_mask(&a, platform),
        BenchCommand::Meshes(a) => super::meshes::run(&a, platform),
        BenchCommand::Igi(a) => super::igi_bench::run(&a, platform),
        BenchCommand::Differentials(a) => super::differentials_bench::run(&a, platform),
        BenchCommand::Mitsuba(a) => super::mitsuba_bench::run(&a, platform),
        BenchCommand::Estimate(a) => super::estimate_bench::run(&a, platform),
        BenchCommand::Build(a) => {
            if a.min_log2 > a.max_log2 {
                bail!(
                    "--min-log2 {} --max-log2 {}: the allowed range is 1 <= min <= max <= 24",
                    a.min_log2,
                    a.max_log2
                );
            }
            let gpu = super::gpu(platform)?;
            let config = photonmap::photon::PhotonConfig {
                grid: a.grid,
                hash_buckets: a.hash_buckets,
                ..Default::default()
            };
            let bench = run_build_bench(
                &gpu,
                (a.min_log2, a.max_log2),
                a.stencil_m,
                &config,
                !a.quiet,
            )?;
            if a.json {
                super::print_json(&bench)
            } else {
                print_build_bench(&bench);
                Ok(())
            }
        }
    }
}

fn run_stress(a: &StressArgs, platform: Platform) -> Result<()> {
    let gpu = super::gpu(platform)?;
    let cases = photonmap::stress::run(&gpu, a.quick, &super::progress_lines(a.quiet));
    for c in &cases {
        if a.json {
            println!("{}", serde_json::to_string(c)?);
        } else {
            println!(
                "{:<8} {:<70} {:>12.5} {:>7.2} s  {}",
                format!("{:?}", c.outcome).to_lowercase(),
                c.name,
                c.value,
                c.seconds,
                c.message
            );
        }
    }
    let count = |o: Outcome| cases.iter().filter(|c| c.outcome == o).count();
    let (pass, fail, refused) = (
        count(Outcome::Pass),
        count(Outcome::Fail),
        count(Outcome::Refused),
    );
    let seconds: f64 = cases.iter().map(|c| c.seconds).sum();
    if a.json {
        let summary = serde_json::json!({ "summary": {
            "cases": cases.len(), "pass": pass, "fail": fail, "refused": refused, "seconds": seconds } });
        println!("{summary}");
    } else {
        println!(
            "{} cases: {pass} pass, {fail} fail, {refused} refused ({seconds:.1} s)",
            cases.len()
        );
    }
    if fail > 0 {
        bail!("{fail} stress cases failed");
    }
    Ok(())
}

fn run_mask(a: &MaskArgs, platform: Platform) -> Result<()> {
    let gpu = super::gpu(platform)?;
    let rows = bench_mask(&gpu, a.size, a.iterations as i32)?;
    if a.json {
        let renderer = gpu.capabilities().gl_renderer;
        println!(
            "{}",
            serde_json::json!({ "renderer": renderer, "size": a.size, "iterations": a.iterations, "rows": rows })
        );
        return Ok(());
    }
    println!(
        "{:>8} {:>11} {:>8} {:>10} {:>9}",
        "masked", "where", "stencil", "wall ms", "relative"
    );
    for r in &rows {
        let place = if r.contiguous { "contiguous" } else { "spread" };
        println!(
            "{:>7.0}% {place:>11} {:>8} {:>10.2} {:>9.3}",
            r.masked_fraction * 100.0,
            r.stencil_test,
            r.wall_seconds * 1e3,
            r.relative
        );
    }
    Ok(())
}

#[derive(serde::Serialize)]
pub struct BuildBench {
    pub renderer: String,
    pub gl_version: String,
    pub rows: Vec<BuildBenchRow>,
}

pub fn run_build_bench(
    gpu: &Gpu,
    (min_log2, max_log2): (u32, u32),
    block: u32,
    config: &photonmap::photon::PhotonConfig,
    progress: bool,
) -> Result<BuildBench> {
    let caps = gpu.capabilities();
    let bar = if progress {
        indicatif::ProgressBar::new((max_log2 - min_log2 + 1) as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut rows = Vec::new();
    for k in min_log2..=max_log2 {
        bar.set_message(format!("n = 2^{k}"));
        let n = 1u64 << k;
        let grid = paper_grid().with_storage(config.storage(n as u32));
        photonmap::photon::check_storage(&grid)?;
        rows.push(bench_size(gpu, n, &grid, block)?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(BuildBench {
        renderer: caps.gl_renderer,
        gl_version: caps.gl_version,
        rows,
    })
}

pub fn print_build_bench(b: &BuildBench) {
    println!("{} ({})", b.renderer, b.gl_version);
    println!(
        "{:>9} {:>6} {:>10} {:>9} {:>9} {:>6} {:>12} {:>9} {:>11} {:>11}",
        "photons",
        "passes",
        "sort ms",
        "pass ms",
        "copy ms",
        "ratio",
        "sort wall ms",
        "search ms",
        "route ms",
        "readback ms"
    );
    for r in &b.rows {
        println!(
            "{:>9} {:>6} {:>10.2} {:>9.3} {:>9.3} {:>6.2} {:>12.2} {:>9.3} {:>11.2} {:>11.2}",
            r.photons,
            r.bitonic_passes,
            r.bitonic_sort_seconds * 1e3,
            r.bitonic_seconds_per_pass * 1e3,
            r.copy_pass_seconds * 1e3,
            r.pass_to_copy_ratio,
            r.bitonic_sort_wall_seconds * 1e3,
            r.binary_search_seconds * 1e3,
            r.stencil_vertex_fetch_seconds * 1e3,
            r.stencil_readback_seconds * 1e3
        );
    }
    println!("fused sort (two long steps a pass, short steps in registers; the same order):");
    println!(
        "{:>9} {:>6} {:>10} {:>9} {:>6} {:>14} {:>12}",
        "photons", "passes", "sort ms", "pass ms", "ratio", "copy passes", "/ faithful"
    );
    for r in &b.rows {
        println!(
            "{:>9} {:>6} {:>10.2} {:>9.3} {:>6.2} {:>14.1} {:>12.2}",
            r.photons,
            r.fused_passes,
            r.fused_sort_seconds * 1e3,
            r.fused_seconds_per_pass * 1e3,
            r.fused_pass_to_copy_ratio,
            r.fused_sort_in_copy_passes,
            r.fused_to_faithful
        );
    }
}
