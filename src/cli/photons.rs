//! `photonmap photons`: trace a scene's photons and build its photon map, and
//! report what happened (counts, passes, per-stage times).

use anyhow::Result;

use photonmap::gpu::Gpu;
use photonmap::photon::{
    BitonicBuild, BuildMethod, PhotonTracer, RandomSource, StencilRouting, TraceReport, VertexFeed,
};
use photonmap::render::Timings;
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::Scene;

#[derive(serde::Serialize)]
pub struct PhotonReport {
    pub scene: String,
    pub seed: u32,
    pub build: BuildMethod,
    pub faithful: bool,
    pub trace: TraceReport,
    pub power_scale: f32,
    pub grid_resolution: [u32; 3],
    pub grid_min: [f32; 3],
    pub grid_max: [f32; 3],
    /// Photons in the map (bitonic: valid sorted records; stencil: records in slots).
    pub photons_in_map: u64,
    /// Photons destined to the grid (inside its bounds).
    pub photons_in_grid: u64,
    pub cells: u32,
    pub cells_with_photons: u32,
    pub max_photons_in_a_cell: u32,
    /// Stencil routing only: cells destined more photons than their m^2 slots.
    pub cells_over_capacity: Option<u32>,
    pub stencil_block: Option<u32>,
    pub timings: Timings,
}

pub struct PhotonOptions {
    pub seed: u32,
    pub build: BuildMethod,
    pub faithful: bool,
    pub feed: VertexFeed,
    pub stencil_block: u32,
    /// Aim photons by projection maps when the scene stores caustics only.
    pub projection_maps: bool,
}

pub fn trace_and_build(gpu: &Gpu, scene: &Scene, o: &PhotonOptions) -> Result<PhotonReport> {
    let textures = SceneTextures::new(gpu, scene)?;
    let random = if o.faithful {
        RandomSource::Texture
    } else {
        RandomSource::Hash
    };
    let mut tracer = PhotonTracer::with_random(gpu, random)?;
    tracer.projection_maps = o.projection_maps;
    let mut timings = Timings::default();
    let wall = std::time::Instant::now();
    let (frames, trace) = tracer.trace_to_stored(scene, &textures, o.seed)?;
    // The kept trace; earlier attempts (choosing the emitted count) are in `trace`.
    timings.add("trace photons", trace.gpu_seconds, frames.frames as usize);
    let grid = photonmap::photon::fit::grid_for(gpu, scene, &frames)?;
    let feed = if o.faithful {
        VertexFeed::Readback
    } else {
        o.feed
    };
    let (in_map, in_grid, per_cell, over, block) = match o.build {
        BuildMethod::Bitonic => {
            let bitonic = BitonicBuild::with_addressing(gpu, o.faithful)?;
            let map = bitonic.build(&frames, &grid, &mut timings)?;
            let first: Vec<i32> = map.grid_first.read_i32().chunks(4).map(|c| c[0]).collect();
            let cells = grid.cell_count() as usize;
            let per_cell: Vec<u32> = (0..cells)
                .map(|c| (first[c + 1] - first[c]) as u32)
                .collect();
            (
                first[cells] as u64,
                first[cells] as u64,
                per_cell,
                None,
                None,
            )
        }
        BuildMethod::Stencil => {
            let map = StencilRouting::new(gpu)?.build(
                &frames,
                &grid,
                o.stencil_block,
                feed,
                &mut timings,
            )?;
            let per_cell: Vec<u32> = map
                .counts
                .read_f32()
                .chunks(4)
                .take(grid.cell_count() as usize)
                .map(|c| c[0] as u32)
                .collect();
            let slots = o.stencil_block * o.stencil_block;
            let in_map: u64 = per_cell.iter().map(|&c| c.min(slots) as u64).sum();
            let over = per_cell.iter().filter(|&&c| c > slots).count() as u32;
            (
                in_map,
                per_cell.iter().map(|&c| c as u64).sum(),
                per_cell,
                Some(over),
                Some(o.stencil_block),
            )
        }
    };
    gpu.finish();
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    Ok(PhotonReport {
        scene: scene.name.clone(),
        seed: o.seed,
        build: o.build,
        faithful: o.faithful,
        power_scale: frames.power_scale,
        trace,
        grid_resolution: grid.resolution,
        grid_min: grid.min.to_array(),
        grid_max: grid.max.to_array(),
        photons_in_map: in_map,
        photons_in_grid: in_grid,
        cells: grid.cell_count(),
        cells_with_photons: per_cell.iter().filter(|&&c| c > 0).count() as u32,
        max_photons_in_a_cell: per_cell.iter().copied().max().unwrap_or(0),
        cells_over_capacity: over,
        stencil_block: block,
        timings,
    })
}

pub fn print_report(r: &PhotonReport) {
    println!(
        "{}: {:?} build{}",
        r.scene,
        r.build,
        if r.faithful { " (faithful)" } else { "" }
    );
    println!(
        "  traced {} photons ({} attempt{}: {:?}); kept the first {} (power x {:.4}); {} stored (target {})",
        r.trace.emitted,
        r.trace.attempts.len(),
        if r.trace.attempts.len() == 1 { "" } else { "s" },
        r.trace.attempts,
        r.trace.photons_used,
        r.power_scale,
        r.trace.stored,
        r.trace.target
    );
    println!(
        "  grid {:?} over {:?}..{:?}: {} in the grid, {} in the map, {} of {} cells used, at most {} in a cell",
        r.grid_resolution, r.grid_min, r.grid_max, r.photons_in_grid, r.photons_in_map, r.cells_with_photons, r.cells, r.max_photons_in_a_cell
    );
    if let Some(p) = &r.trace.projection {
        println!(
            "  caustics only, aimed by projection maps: {} of {} cells kept ({}x{} a light), {:.2}% of the lights' power",
            p.kept_cells,
            p.cells,
            p.resolution,
            p.resolution,
            100.0 * p.kept_power_fraction
        );
    }
    if let (Some(over), Some(m)) = (r.cells_over_capacity, r.stencil_block) {
        println!("  stencil routing m = {m} ({} slots a cell): {over} cells over capacity, their power redistributed", m * m);
    }
    if r.trace.attempts.len() > 1 {
        println!(
            "  (earlier attempts to reach the stored count: {:.2} ms more GPU time)",
            (r.trace.gpu_seconds_all_attempts - r.trace.gpu_seconds) * 1e3
        );
    }
    print!("{}", r.timings.table());
}
