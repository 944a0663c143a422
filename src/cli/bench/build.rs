//! `photonmap bench build`: the photon-map builds of src/bench/build.rs
//! for n = 2^min .. 2^max synthetic photons, as two tables or JSON.

use anyhow::{bail, Result};
use clap::Args;

use photonmap::bench::build::{bench_size, paper_grid, BuildBenchRow};
use photonmap::gpu::{Gpu, Platform};
use photonmap::photon::build::MAX_HASH_BUCKETS;
use photonmap::photon::{GridKind, PhotonConfig};

use super::output::BenchOutput;
use crate::cli::args::in_range;

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
    #[arg(long, value_enum, default_value_t = GridKind::Uniform)]
    pub grid: GridKind,
    /// Hash buckets of `--grid hash` (1..=16777216; default: the next power of two >= the photons).
    #[arg(long, value_name = "N", value_parser = in_range(1, MAX_HASH_BUCKETS))]
    pub hash_buckets: Option<u32>,
    #[command(flatten)]
    pub output: BenchOutput,
}

pub fn run(a: &BuildArgs, platform: Platform) -> Result<()> {
    if a.min_log2 > a.max_log2 {
        bail!(
            "--min-log2 {} --max-log2 {}: the allowed range is 1 <= min <= max <= 24",
            a.min_log2,
            a.max_log2
        );
    }
    let gpu = crate::cli::gpu(platform)?;
    let config = PhotonConfig {
        grid: a.grid,
        hash_buckets: a.hash_buckets,
        ..Default::default()
    };
    let bench = run_build_bench(
        &gpu,
        (a.min_log2, a.max_log2),
        a.stencil_m,
        &config,
        !a.output.quiet,
    )?;
    a.output.print(&bench, print_build_bench)
}

#[derive(serde::Serialize)]
pub struct BuildBench {
    pub renderer: String,
    pub gl_version: String,
    pub rows: Vec<BuildBenchRow>,
}

fn run_build_bench(
    gpu: &Gpu,
    (min_log2, max_log2): (u32, u32),
    block: u32,
    config: &PhotonConfig,
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

fn print_build_bench(b: &BuildBench) {
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
    println!("counting build (the default; the same map), whole builds:");
    println!(
        "{:>9} {:>6} {:>10} {:>9} {:>9} {:>9} {:>10} {:>12} {:>11} {:>11}",
        "photons",
        "passes",
        "compact ms",
        "prefix ms",
        "place ms",
        "gather ms",
        "build ms",
        "copy passes",
        "bitonic ms",
        "/ bitonic"
    );
    for r in &b.rows {
        println!(
            "{:>9} {:>6} {:>10.2} {:>9.2} {:>9.2} {:>9.2} {:>10.2} {:>12.1} {:>11.2} {:>11.3}",
            r.photons,
            r.counting_passes,
            r.counting_compact_seconds * 1e3,
            r.counting_prefix_seconds * 1e3,
            r.counting_place_seconds * 1e3,
            r.counting_gather_seconds * 1e3,
            r.counting_seconds * 1e3,
            r.counting_in_copy_passes,
            r.bitonic_build_seconds * 1e3,
            r.counting_to_bitonic
        );
    }
}
