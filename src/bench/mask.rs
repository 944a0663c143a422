//! `photonmap bench mask`: whether the stencil test skips fragment work on
//! this driver (the computation mask of section 4.3): an expensive
//! full-screen pass with a share of its pixels masked.

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};

/// One row of `bench mask`: an expensive full-screen pass with a share of its
/// pixels masked by the stencil test.
#[derive(Clone, Debug, serde::Serialize)]
pub struct MaskBenchRow {
    pub masked_fraction: f64,
    /// Masked pixels in one block (the left of the image) or spread evenly.
    pub contiguous: bool,
    pub stencil_test: bool,
    pub wall_seconds: f64,
    /// wall_seconds / the unmasked pass's: 1 - masked_fraction if masked work is skipped.
    pub relative: f64,
}

/// Does the stencil test skip fragment work on this driver? Times a heavy pass
/// over `size` x `size` pixels with 0%, 50% and 90% of them masked.
pub fn bench_mask(gpu: &Gpu, size: u32, iterations: i32) -> Result<Vec<MaskBenchRow>> {
    let tex = Texture::new(gpu, size, size, TexFormat::Rgba32F)?;
    let target = Target::with_stencil(gpu, &[&tex])?;
    let heavy = Program::fullscreen(gpu, "bench/heavy.frag")?;
    let pattern = Program::fullscreen(gpu, "bench/mask_pattern.frag")?;
    let run = |tenths: i32, contiguous: bool, stencil: bool| -> Result<f64> {
        target.clear_depth_stencil(1.0, 0);
        let state = if stencil {
            pattern
                .bind()
                .int("u_masked_tenths", tenths)
                .int("u_contiguous", contiguous as i32)
                .int("u_width", size as i32)
                .draw_fullscreen(&target, &DrawState::stencil_replace(1))?;
            DrawState::where_stencil_equals(0)
        } else {
            DrawState::PLAIN
        };
        gpu.finish();
        let t0 = std::time::Instant::now();
        heavy
            .bind()
            .int("u_iterations", iterations)
            .draw_fullscreen(&target, &state)?;
        gpu.finish();
        Ok(t0.elapsed().as_secs_f64())
    };
    run(0, false, false)?; // warm-up: compile and first touch
    let base = run(0, false, false)?;
    let mut rows = vec![MaskBenchRow {
        masked_fraction: 0.0,
        contiguous: false,
        stencil_test: false,
        wall_seconds: base,
        relative: 1.0,
    }];
    for (tenths, contiguous) in [(0, false), (5, false), (9, false), (5, true), (9, true)] {
        let s = run(tenths, contiguous, true)?;
        rows.push(MaskBenchRow {
            masked_fraction: tenths as f64 / 10.0,
            contiguous,
            stencil_test: true,
            wall_seconds: s,
            relative: s / base,
        });
    }
    gpu.check("mask benchmark")?;
    Ok(rows)
}
