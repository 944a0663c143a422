//! `photonmap bench mask`: whether the stencil test skips fragment work on
//! this driver (src/bench/mask.rs), as a table or JSON.

use anyhow::Result;
use clap::Args;

use photonmap::bench::mask::bench_mask;
use photonmap::gpu::Platform;

use crate::cli::args::in_range;

#[derive(Args)]
pub struct MaskArgs {
    /// Side of the square pass in pixels (16..=8192).
    #[arg(long, default_value_t = 512, value_parser = in_range(16, 8192))]
    pub size: u32,
    /// Rounds of sin/cos per pixel (1..=100000).
    #[arg(long, default_value_t = 200, value_parser = in_range(1, 100_000))]
    pub iterations: u32,
    /// The report on stdout as JSON, not a table.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &MaskArgs, platform: Platform) -> Result<()> {
    let gpu = crate::cli::gpu(platform)?;
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
