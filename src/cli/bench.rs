//! `photonmap bench build`: the photon-map builds against n.

use anyhow::{bail, Result};

use photonmap::gpu::Gpu;
use photonmap::photon::bench::{bench_size, paper_grid, BuildBenchRow};

#[derive(serde::Serialize)]
pub struct BuildBench {
    pub renderer: String,
    pub gl_version: String,
    pub rows: Vec<BuildBenchRow>,
}

pub fn run_build_bench(
    gpu: &Gpu,
    min_log2: u32,
    max_log2: u32,
    block: u32,
    progress: bool,
) -> Result<BuildBench> {
    if !(1..=24).contains(&min_log2) || !(min_log2..=24).contains(&max_log2) {
        bail!("--min-log2 {min_log2} --max-log2 {max_log2}: the allowed range is 1 <= min <= max <= 24");
    }
    let caps = gpu.capabilities();
    let bar = if progress {
        indicatif::ProgressBar::new((max_log2 - min_log2 + 1) as u64)
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut rows = Vec::new();
    for k in min_log2..=max_log2 {
        bar.set_message(format!("n = 2^{k}"));
        rows.push(bench_size(gpu, 1u64 << k, &paper_grid(), block)?);
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
}
