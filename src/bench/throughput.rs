//! The library half of `photonmap bench throughput`: where an SPPM
//! iteration's time goes by stage, the time of a direct-light render, and
//! the floor this substrate sets under any pass: one copy pass over as many
//! texels as the stage has records.

use std::time::Instant;

use super::copy::CopyPasses;
use crate::gpu::{Gpu, Result, TexFormat};
use crate::render::sppm::{render_sppm, SppmOptions};
use crate::render::{render, RenderOptions};
use crate::scene::Scene;

/// A stage's wall seconds an SPPM iteration.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StageSeconds {
    pub name: String,
    pub seconds: f64,
}

/// Wall seconds an SPPM iteration spends in each stage: for each stage,
/// (its least time over `repeats` runs of `long` iterations - its least over
/// as many runs of `short`) / (long - short), so that start-up and shader
/// compilation drop out. (The least of each length, not the least of the
/// differences: that would pick the pair whose short run the machine slowed.)
pub fn sppm_stage_seconds(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    sppm: &SppmOptions,
    (short, long, repeats): (u32, u32, u32),
) -> Result<Vec<StageSeconds>> {
    assert!(long > short, "the long run must be the longer");
    // Each stage's least wall seconds over `repeats` runs of `iterations`.
    let least = |iterations: u32| -> Result<Vec<StageSeconds>> {
        let o = SppmOptions {
            iterations,
            seconds: None,
            ..sppm.clone()
        };
        let mut best: Vec<StageSeconds> = Vec::new();
        for _ in 0..repeats.max(1) {
            let out = render_sppm(gpu, scene, options, &o, &mut ())?;
            for s in &out.timings.stages {
                match best.iter_mut().find(|b| b.name == s.name) {
                    Some(b) => b.seconds = b.seconds.min(s.wall_seconds),
                    None => best.push(StageSeconds {
                        name: s.name.clone(),
                        seconds: s.wall_seconds,
                    }),
                }
            }
        }
        Ok(best)
    };
    let (a, b) = (least(short)?, least(long)?);
    Ok(b.into_iter()
        .map(|stage| {
            let before = a
                .iter()
                .find(|s| s.name == stage.name)
                .map_or(0.0, |s| s.seconds);
            StageSeconds {
                seconds: (stage.seconds - before) / f64::from(long - short),
                name: stage.name,
            }
        })
        .collect())
}

/// Wall seconds of a whole render at `options` (direct light only, for
/// the benchmark): the fastest of `repeats`, after one that compiles.
pub fn render_seconds(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    repeats: u32,
) -> Result<f64> {
    render(gpu, scene, options, &mut ())?;
    let mut best = f64::INFINITY;
    for _ in 0..repeats.max(1) {
        gpu.finish();
        let start = Instant::now();
        render(gpu, scene, options, &mut ())?;
        gpu.finish();
        best = best.min(start.elapsed().as_secs_f64());
    }
    Ok(best)
}

/// Wall seconds of one full-screen pass that copies `texels` 16-byte
/// texels (a square-ish texture; the size of a float record): the mean of
/// 8 passes, the least of `repeats` such batches.
pub fn copy_pass_seconds(gpu: &Gpu, texels: u64, repeats: u32) -> Result<f64> {
    let width = (texels as f64).sqrt().ceil().max(1.0) as u32;
    let height = texels.div_ceil(u64::from(width)).max(1) as u32;
    let copy = CopyPasses::new(gpu, width, height, TexFormat::Rgba32I)?;
    const BATCH: usize = 8;
    let mut best = f64::INFINITY;
    for _ in 0..=repeats.max(1) {
        gpu.finish();
        let start = Instant::now();
        copy.run(BATCH)?;
        gpu.finish();
        best = best.min(start.elapsed().as_secs_f64() / BATCH as f64);
    }
    Ok(best)
}
