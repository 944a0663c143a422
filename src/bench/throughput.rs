//! The library half of `photonmap bench throughput`: where an SPPM
//! iteration's time goes by stage, the time of a direct-light render, and
//! the floor this substrate sets under any pass: one copy pass over as many
//! texels as the stage has records.

use std::time::Instant;

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::render::sppm::{render_sppm, SppmOptions};
use crate::render::{render, RenderOptions};
use crate::scene::Scene;

/// A stage's wall seconds an SPPM iteration.
#[derive(Clone, Debug, serde::Serialize)]
pub struct StageSeconds {
    pub name: String,
    pub seconds: f64,
}

/// Wall seconds an SPPM iteration spends in each stage: for each stage, the
/// least over `repeats` of (a run of `long` iterations - a run of `short`)
/// / (long - short), so that start-up and shader compilation drop out.
pub fn sppm_stage_seconds(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    sppm: &SppmOptions,
    (short, long, repeats): (u32, u32, u32),
) -> Result<Vec<StageSeconds>> {
    assert!(long > short, "the long run must be the longer");
    let run = |iterations: u32| -> Result<Vec<StageSeconds>> {
        let o = SppmOptions {
            iterations,
            seconds: None,
            ..sppm.clone()
        };
        let out = render_sppm(gpu, scene, options, &o, &mut ())?;
        Ok(out
            .timings
            .stages
            .iter()
            .map(|s| StageSeconds {
                name: s.name.clone(),
                seconds: s.wall_seconds,
            })
            .collect())
    };
    let mut best: Vec<StageSeconds> = Vec::new();
    for _ in 0..repeats.max(1) {
        let (a, b) = (run(short)?, run(long)?);
        for stage in &b {
            let before = a
                .iter()
                .find(|s| s.name == stage.name)
                .map_or(0.0, |s| s.seconds);
            let seconds = (stage.seconds - before) / f64::from(long - short);
            match best.iter_mut().find(|s| s.name == stage.name) {
                Some(s) => s.seconds = s.seconds.min(seconds),
                None => best.push(StageSeconds {
                    name: stage.name.clone(),
                    seconds,
                }),
            }
        }
    }
    Ok(best)
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

/// Wall seconds of one full-screen pass that copies `texels` RGBA32F
/// texels (a square-ish texture): the mean of 8 passes ping-ponged, the
/// least of `repeats` such batches.
pub fn copy_pass_seconds(gpu: &Gpu, texels: u64, repeats: u32) -> Result<f64> {
    let width = (texels as f64).sqrt().ceil().max(1.0) as u32;
    let height = texels.div_ceil(u64::from(width)).max(1) as u32;
    let textures = [
        Texture::new(gpu, width, height, TexFormat::Rgba32F)?,
        Texture::new(gpu, width, height, TexFormat::Rgba32F)?,
    ];
    let targets = [
        Target::new(gpu, &[&textures[0]])?,
        Target::new(gpu, &[&textures[1]])?,
    ];
    let copy = Program::fullscreen(gpu, "bench/copy_texels.frag")?;
    const BATCH: usize = 8;
    let mut best = f64::INFINITY;
    for _ in 0..=repeats.max(1) {
        gpu.finish();
        let start = Instant::now();
        for i in 0..BATCH {
            copy.bind()
                .texture("u_texels", &textures[i % 2])
                .draw_fullscreen(&targets[1 - i % 2], &DrawState::PLAIN)?;
        }
        gpu.finish();
        best = best.min(start.elapsed().as_secs_f64() / BATCH as f64);
    }
    Ok(best)
}
