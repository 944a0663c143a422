//! `photonmap photons`: trace a scene's photons and build its photon map, and
//! report what happened (counts, passes, per-stage times).

use anyhow::Result;
use clap::Args;

use photonmap::gpu::{Gpu, Platform};
use photonmap::photon::{build_map, BuildMethod, PhotonConfig, PhotonMap, TraceReport};
use photonmap::render::Timings;
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::Scene;

use super::args::PhotonMapArgs;

/// Trace a scene's photons and build its photon map; report counts, passes and times.
#[derive(Args)]
pub struct PhotonsArgs {
    #[command(flatten)]
    pub scene: super::args::SceneArgs,
    #[command(flatten)]
    pub photons: PhotonMapArgs,
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// As JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &PhotonsArgs, platform: Platform) -> Result<()> {
    let loaded = args.scene.load()?;
    let gpu = super::gpu(platform)?;
    let mut report = trace_and_build(&gpu, &loaded.scene, &(&args.photons).into(), args.seed)?;
    let mut provenance = super::with_driver(loaded.provenance, &gpu);
    (provenance.method, provenance.seed) = ("photons".into(), args.seed);
    report.provenance = Some(provenance);
    if args.json {
        super::print_json(&report)
    } else {
        print_report(&report);
        Ok(())
    }
}

#[derive(serde::Serialize)]
pub struct PhotonReport {
    pub provenance: Option<photonmap::provenance::Provenance>,
    pub scene: String,
    pub seed: u32,
    pub build: BuildMethod,
    pub faithful: bool,
    pub trace: TraceReport,
    pub power_scale: f32,
    pub grid_resolution: [u32; 3],
    pub grid_min: [f32; 3],
    pub grid_max: [f32; 3],
    /// Uniform (a slot per cell) or hashed (a slot per bucket; section 4.4).
    pub grid_storage: photonmap::photon::GridStorage,
    /// Texels of the grid's structure (`PhotonMap::grid_texels`).
    pub grid_texels: u64,
    /// Hashed stencil routing: photons of cells their full bucket kept none
    /// of, and the fraction of the routed power they carried (lost).
    pub lost_photons: Option<u64>,
    pub lost_power_fraction: Option<f64>,
    /// Photons in the map (bitonic: valid sorted records; stencil: records in slots).
    pub photons_in_map: u64,
    /// Photons destined to the grid (inside its bounds).
    pub photons_in_grid: u64,
    pub cells: u32,
    /// Slots (cells, or hash buckets) holding photons, and the most in one.
    pub cells_with_photons: u32,
    pub max_photons_in_a_cell: u32,
    /// Stencil routing only: cells destined more photons than their m^2 slots.
    pub cells_over_capacity: Option<u32>,
    pub stencil_block: Option<u32>,
    pub timings: Timings,
}

pub fn trace_and_build(
    gpu: &Gpu,
    scene: &Scene,
    config: &PhotonConfig,
    seed: u32,
) -> Result<PhotonReport> {
    let textures = SceneTextures::new(gpu, scene)?;
    let mut totals = Timings::default();
    let wall = std::time::Instant::now();
    let built = build_map(gpu, scene, &textures, config, seed, &mut totals)?;
    // Tracing, then the build's own stages (not their total, which would count them twice).
    let mut timings = Timings::default();
    timings.stages.extend(
        totals
            .stages
            .into_iter()
            .filter(|s| s.name == "trace photons"),
    );
    timings
        .stages
        .extend(built.build_stages.stages.iter().cloned());
    let per_cell = built.map.photons_per_cell();
    let in_grid: u64 = per_cell.iter().map(|&c| c as u64).sum();
    let (in_map, over, block) = match &built.map {
        PhotonMap::Sorted(_) => (in_grid, None, None),
        PhotonMap::Routed(m) => {
            let slots = m.block * m.block;
            let in_map: u64 = per_cell.iter().map(|&c| c.min(slots) as u64).sum();
            let over = per_cell.iter().filter(|&&c| c > slots).count() as u32;
            (in_map, Some(over), Some(m.block))
        }
    };
    gpu.finish();
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    let grid = built.grid;
    let lost = match &built.map {
        PhotonMap::Routed(m) => m.lost,
        PhotonMap::Sorted(_) => None,
    };
    Ok(PhotonReport {
        provenance: None,
        scene: scene.name.clone(),
        seed,
        build: config.build,
        faithful: config.faithful,
        power_scale: built.power_scale,
        trace: built.trace,
        grid_resolution: grid.resolution,
        grid_min: grid.min.to_array(),
        grid_max: grid.max.to_array(),
        grid_storage: grid.storage,
        grid_texels: built.map.grid_texels(),
        lost_photons: lost.map(|l| l.photons),
        lost_power_fraction: lost.map(|l| l.fraction()),
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
        "{}: {} build{}",
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
        "  grid {} x {} x {} cells over ({}, {}, {})..({}, {}, {}): {} in the grid, {} in the map, {} of {} cells used, at most {} in a cell",
        r.grid_resolution[0], r.grid_resolution[1], r.grid_resolution[2],
        r.grid_min[0], r.grid_min[1], r.grid_min[2], r.grid_max[0], r.grid_max[1], r.grid_max[2],
        r.photons_in_grid, r.photons_in_map, r.cells_with_photons, r.cells, r.max_photons_in_a_cell
    );
    if let photonmap::photon::GridStorage::Hashed { buckets } = r.grid_storage {
        println!(
            "  hashed into {buckets} buckets (section 4.4): the counts above are per bucket; {} grid texels",
            r.grid_texels
        );
    } else {
        println!("  uniform grid: {} grid texels", r.grid_texels);
    }
    if let (Some(n), Some(f)) = (r.lost_photons, r.lost_power_fraction) {
        println!(
            "  {n} photons of cells their full bucket kept none of: {:.3}% of the routed power is lost",
            100.0 * f
        );
    }
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
