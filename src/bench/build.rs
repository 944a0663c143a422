//! `photonmap bench build`: the photon-map builds on n = 2^k synthetic photons
//! (the counting build, the bitonic sort's faithful passes and its fused
//! ones, stencil routing), beside a plain copy pass over the same texture
//! (the bandwidth bound).

use glam::Vec3;

use super::copy::CopyPasses;
use crate::gpu::{Gpu, Query, Result, TexFormat};
use crate::photon::bitonic::BitonicBuild;
use crate::photon::compaction::sort_texture_size;
use crate::photon::{CountingBuild, Grid, GridStorage, PhotonFrames, StencilRouting, VertexFeed};
use crate::timing::{StageTiming, Timings};

#[derive(Clone, Debug, serde::Serialize)]
pub struct BuildBenchRow {
    pub photons: u64,
    pub bitonic_passes: u32,
    pub bitonic_sort_seconds: f64,
    pub bitonic_seconds_per_pass: f64,
    pub copy_pass_seconds: f64,
    /// Wall clock (glFinish before and after) of the sort and of one copy pass.
    pub bitonic_sort_wall_seconds: f64,
    pub copy_pass_wall_seconds: f64,
    /// bitonic_seconds_per_pass / copy_pass_seconds (target: <= 1.5)
    pub pass_to_copy_ratio: f64,
    /// The fused sort (`fused_plan`): its passes, GPU seconds, seconds per
    /// pass, that against a copy pass, its time in copy passes (the faithful
    /// sort's is passes x ratio), and its time over the faithful sort's.
    pub fused_passes: u32,
    pub fused_sort_seconds: f64,
    pub fused_seconds_per_pass: f64,
    pub fused_pass_to_copy_ratio: f64,
    pub fused_sort_in_copy_passes: f64,
    pub fused_to_faithful: f64,
    pub keys_seconds: f64,
    pub binary_search_seconds: f64,
    pub gather_seconds: f64,
    pub stencil_block: u32,
    pub stencil_cells: u32,
    /// GPU time of routing (pattern + route + count + redistribute), vertex fetch.
    pub stencil_vertex_fetch_seconds: f64,
    /// The same with the paper's read-back: GPU time plus the read-back's wall time.
    pub stencil_readback_seconds: f64,
    pub stencil_readback_wall_seconds: f64,
    /// The whole bitonic build (compaction, sort, binary search, gather), GPU seconds.
    pub bitonic_build_seconds: f64,
    /// The counting build (the default), GPU seconds by stage, its passes,
    /// and its whole time in copy passes and over the bitonic build's.
    pub counting_compact_seconds: f64,
    pub counting_prefix_seconds: f64,
    pub counting_place_seconds: f64,
    pub counting_gather_seconds: f64,
    pub counting_seconds: f64,
    pub counting_passes: u32,
    pub counting_in_copy_passes: f64,
    pub counting_to_bitonic: f64,
}

/// Photons at uniform random points of the unit cube, all stored, one frame.
pub fn synthetic_frames(gpu: &Gpu, n: u64, seed: u32) -> Result<PhotonFrames> {
    let (width, height) = sort_texture_size(n);
    let mut state = seed;
    let mut next = || crate::random::rng_next(&mut state);
    PhotonFrames::one_frame(gpu, width, width * height, |_| {
        [[next(), next(), next(), 0.0], [1.0; 4], [0.0; 4]]
    })
}

fn stage(t: &Timings, name: &str) -> f64 {
    t.stages
        .iter()
        .filter(|s| s.name == name)
        .map(|s| s.gpu_seconds)
        .sum()
}

/// The sort's stage of a bitonic build.
fn sort_stage(t: &Timings) -> StageTiming {
    t.stages
        .iter()
        .find(|s| s.name == "bitonic sort")
        .cloned()
        .unwrap_or_default()
}

/// Benchmarks one size. `grid` is the paper's ~40^3 cells; `block` is m.
pub fn bench_size(gpu: &Gpu, n: u64, grid: &Grid, block: u32) -> Result<BuildBenchRow> {
    let frames = synthetic_frames(gpu, n, 0x5eed)?;
    let bitonic = BitonicBuild::new(gpu)?.fusing(false);
    let fused = BitonicBuild::new(gpu)?.fusing(true);
    let routing = StencilRouting::new(gpu)?;
    // Warm-up: compile, first-touch allocation.
    bitonic.build(&frames, grid, &mut Timings::default())?;
    let mut t = Timings::default();
    bitonic.build(&frames, grid, &mut t)?;
    let sort = sort_stage(&t);

    // Copy passes over the same RGBA32I texture, ping-ponged like the sort (each
    // reads what the last wrote), as many as the sort has passes.
    let (w, h) = sort_texture_size(n);
    let copy = CopyPasses::new(gpu, w, h, TexFormat::Rg32I)?;
    let copies = sort.passes.max(1);
    let q = Query::timer(gpu)?;
    gpu.finish();
    let wall = std::time::Instant::now();
    q.begin();
    copy.run(copies)?;
    q.end();
    gpu.finish();
    let copy_wall = wall.elapsed().as_secs_f64() / copies as f64;
    let copy_pass = q.seconds() / copies as f64;

    // The sort again under the wall clock, to cross-check the timer queries.
    let keys = {
        let mut t = Timings::default();
        let map = bitonic.build(&frames, grid, &mut t)?;
        map.pairs
    };
    gpu.finish();
    let wall = std::time::Instant::now();
    let (_, passes) = bitonic.sort(keys)?;
    gpu.finish();
    let sort_wall = wall.elapsed().as_secs_f64();

    routing.build(
        &frames,
        grid,
        block,
        VertexFeed::VertexFetch,
        &mut Timings::default(),
    )?;
    let mut fetch = Timings::default();
    routing.build(&frames, grid, block, VertexFeed::VertexFetch, &mut fetch)?;
    let mut readback = Timings::default();
    routing.build(&frames, grid, block, VertexFeed::Readback, &mut readback)?;
    let gpu_part = |t: &Timings| {
        ["route", "count", "count cells", "redistribute"]
            .iter()
            .map(|s| stage(t, s))
            .sum::<f64>()
    };
    let readback_wall = stage(&readback, "read-back (wall)");
    let per_pass = sort.gpu_seconds / sort.passes.max(1) as f64;
    fused.build(&frames, grid, &mut Timings::default())?;
    let mut tf = Timings::default();
    fused.build(&frames, grid, &mut tf)?;
    let fused_sort = sort_stage(&tf);
    let counting = CountingBuild::new(gpu)?;
    counting.build(&frames, grid, &mut Timings::default())?;
    let mut tc = Timings::default();
    counting.build(&frames, grid, &mut tc)?;
    let counting_seconds: f64 = tc.stages.iter().map(|s| s.gpu_seconds).sum();
    let bitonic_build_seconds: f64 = t.stages.iter().map(|s| s.gpu_seconds).sum();
    Ok(BuildBenchRow {
        photons: n,
        bitonic_passes: sort.passes as u32,
        bitonic_sort_seconds: sort.gpu_seconds,
        bitonic_seconds_per_pass: per_pass,
        copy_pass_seconds: copy_pass,
        bitonic_sort_wall_seconds: sort_wall * sort.passes as f64 / passes.max(1) as f64,
        copy_pass_wall_seconds: copy_wall,
        pass_to_copy_ratio: per_pass / copy_pass,
        fused_passes: fused_sort.passes as u32,
        fused_sort_seconds: fused_sort.gpu_seconds,
        fused_seconds_per_pass: fused_sort.gpu_seconds / fused_sort.passes.max(1) as f64,
        fused_pass_to_copy_ratio: fused_sort.gpu_seconds
            / fused_sort.passes.max(1) as f64
            / copy_pass,
        fused_sort_in_copy_passes: fused_sort.gpu_seconds / copy_pass,
        fused_to_faithful: fused_sort.gpu_seconds / sort.gpu_seconds,
        keys_seconds: stage(&t, "keys"),
        binary_search_seconds: stage(&t, "binary search"),
        gather_seconds: stage(&t, "gather"),
        stencil_block: block,
        stencil_cells: grid.cell_count(),
        stencil_vertex_fetch_seconds: gpu_part(&fetch),
        stencil_readback_seconds: gpu_part(&readback) + readback_wall,
        stencil_readback_wall_seconds: readback_wall,
        bitonic_build_seconds,
        counting_compact_seconds: stage(&tc, "compact and count"),
        counting_prefix_seconds: stage(&tc, "prefix sums"),
        counting_place_seconds: stage(&tc, "place"),
        counting_gather_seconds: stage(&tc, "gather"),
        counting_seconds,
        counting_passes: tc.stages.iter().map(|s| s.passes as u32).sum(),
        counting_in_copy_passes: counting_seconds / copy_pass,
        counting_to_bitonic: counting_seconds / bitonic_build_seconds,
    })
}

/// The paper's stencil-routing grid: about 40^3 cells over the unit cube.
pub fn paper_grid() -> Grid {
    Grid {
        min: Vec3::ZERO,
        max: Vec3::ONE,
        resolution: [40, 40, 40],
        storage: GridStorage::Uniform,
    }
}
