//! The photon half of Figure 1 in one call: trace photons until the map can
//! hold the scene's `photons_stored`, choose the grid, and build the map by
//! bitonic sort or stencil routing. `render`, `photonmap photons` and the
//! benchmarks all build their maps here.

use crate::gpu::{Gpu, Result};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

use super::trace::{PhotonFrames, TraceConfig, TraceReport};
use super::{
    fit, BitonicBuild, BuildMethod, CountingBuild, Grid, GridKind, GridStorage, PhotonMap,
    PhotonTracer, RandomSource, StencilRouting, VertexFeed,
};

/// How photons are traced and the map built (what the scene file does not fix).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct PhotonConfig {
    pub build: BuildMethod,
    /// Stencil routing: m, each cell holds m x m photons.
    pub stencil_block: u32,
    pub feed: VertexFeed,
    /// The paper's 2003 constraints: a random-number texture, read-back before
    /// routing, float addressing, no compaction.
    pub faithful: bool,
    /// Trace every bounce up to max_bounces even when no photon is left alive.
    pub all_bounces: bool,
    /// Aim photons by projection maps when the scene stores caustics only.
    pub projection_maps: bool,
    /// Uniform grid, or a hash table of cells (section 4.4).
    pub grid: GridKind,
    /// Hash buckets (None: the next power of two >= the photons stored).
    pub hash_buckets: Option<u32>,
}

impl Default for PhotonConfig {
    fn default() -> Self {
        Self {
            build: BuildMethod::Counting,
            stencil_block: 4,
            feed: VertexFeed::VertexFetch,
            faithful: false,
            all_bounces: false,
            projection_maps: true,
            grid: GridKind::Uniform,
            hash_buckets: None,
        }
    }
}

impl PhotonConfig {
    /// The build that runs: `--faithful` takes the paper's bitonic sort
    /// where the counting build (the default) is asked for.
    pub fn build_method(&self) -> BuildMethod {
        match self.build {
            BuildMethod::Counting if self.faithful => BuildMethod::Bitonic,
            build => build,
        }
    }

    /// The tracer's configuration: `--faithful` takes the random-number texture.
    pub fn trace(&self) -> TraceConfig {
        TraceConfig {
            random: if self.faithful {
                RandomSource::Texture
            } else {
                RandomSource::Hash
            },
            stop_when_dead: !self.all_bounces,
            projection_maps: self.projection_maps,
            fused: false,
        }
    }

    /// How the grid stores its cells for a scene storing `photons_stored`.
    pub fn storage(&self, photons_stored: u32) -> GridStorage {
        match self.grid {
            GridKind::Uniform => GridStorage::Uniform,
            GridKind::Hash => GridStorage::Hashed {
                buckets: self
                    .hash_buckets
                    .unwrap_or_else(|| default_hash_buckets(photons_stored)),
            },
        }
    }

    /// How records reach stencil routing: `--faithful` reads them back.
    pub fn feed(&self) -> VertexFeed {
        if self.faithful {
            VertexFeed::Readback
        } else {
            self.feed
        }
    }
}

/// The most hash buckets (`--hash-buckets`): the photons a map may store.
pub const MAX_HASH_BUCKETS: u32 = crate::scene::defaults::MAX_PHOTONS_STORED as u32;

/// `--hash-buckets`' default: the next power of two >= the photons stored
/// (a load factor of at most 1).
pub fn default_hash_buckets(photons_stored: u32) -> u32 {
    super::next_power_of_two(photons_stored as u64).min(MAX_HASH_BUCKETS as u64) as u32
}

/// Refuses a grid its storage cannot hold: a uniform grid of more than
/// MAX_UNIFORM_GRID_CELLS, a hash table of 0 or more than MAX_HASH_BUCKETS buckets.
pub fn check_storage(grid: &Grid) -> Result<()> {
    use crate::error::Error;
    use crate::scene::defaults::MAX_UNIFORM_GRID_CELLS;
    let [x, y, z] = grid.resolution;
    match grid.storage {
        GridStorage::Uniform if grid.cells_u64() > MAX_UNIFORM_GRID_CELLS => {
            Err(Error::InvalidOption(format!(
                "a uniform grid of {x} x {y} x {z} = {} cells: a uniform grid stores at most {MAX_UNIFORM_GRID_CELLS} cells (512^3), one texel each; use --grid hash, whose memory follows the photons, not the cells",
                grid.cells_u64()
            )))
        }
        GridStorage::Hashed { buckets } if !(1..=MAX_HASH_BUCKETS).contains(&buckets) => {
            Err(Error::InvalidOption(format!(
                "{buckets} hash buckets: the allowed range is 1..={MAX_HASH_BUCKETS}"
            )))
        }
        _ => Ok(()),
    }
}

/// A photon map and what it took to make it.
pub struct BuiltMap {
    pub map: PhotonMap,
    pub trace: TraceReport,
    /// Photon frames traced (emission + bounces; fewer than max_bounces + 1
    /// when tracing stopped with no photon alive).
    pub frames_traced: u32,
    /// The power each kept photon carries relative to one of all traced.
    pub power_scale: f32,
    pub grid: Grid,
    /// Whether the grid's bounds were fitted to the photons (the scene fixes none).
    pub grid_fitted: bool,
    /// The build's own stages (keys or compaction, sort, search, gather; or
    /// pattern, route, count, redistribute).
    pub build_stages: Timings,
    /// The traced records the map was built from, for passes that want each
    /// stored photon's primitive (radiosity's caustic deposit).
    pub frames: PhotonFrames,
}

/// `PhotonTracer::trace_to_stored`, added to `timings` as "trace photons":
/// wall time over every attempt at the stored count, GPU time of the kept trace.
pub fn trace_timed(
    gpu: &Gpu,
    tracer: &PhotonTracer,
    scene: &Scene,
    textures: &SceneTextures,
    seed: u32,
    timings: &mut Timings,
) -> Result<(super::PhotonFrames, TraceReport)> {
    gpu.finish();
    let t0 = std::time::Instant::now();
    let (frames, trace) = tracer.trace_to_stored(scene, textures, seed)?;
    gpu.finish();
    timings.add_since(
        "trace photons",
        trace.gpu_seconds,
        t0,
        frames.frames as usize,
    );
    Ok((frames, trace))
}

/// Traces the scene's photons and builds its map, adding the stages "trace
/// photons" and "build map" (GPU time and wall clock) to `timings`.
pub fn build_map(
    gpu: &Gpu,
    scene: &Scene,
    textures: &SceneTextures,
    config: &PhotonConfig,
    seed: u32,
    timings: &mut Timings,
) -> Result<BuiltMap> {
    let tracer = PhotonTracer::with_config(gpu, config.trace())?;
    let (frames, trace) = trace_timed(gpu, &tracer, scene, textures, seed, timings)?;
    // The scene's grid bounds, or (when it fixes none) the box of the photons.
    let grid = fit::grid_for(gpu, scene, &frames)?
        .with_storage(config.storage(scene.photon_map.photons_stored));
    check_storage(&grid)?;
    let mut build_stages = Timings::default();
    let t0 = std::time::Instant::now();
    let map = match config.build_method() {
        BuildMethod::Counting => {
            PhotonMap::Sorted(CountingBuild::new(gpu)?.build(&frames, &grid, &mut build_stages)?)
        }
        BuildMethod::Bitonic => {
            PhotonMap::Sorted(BitonicBuild::with_addressing(gpu, config.faithful)?.build(
                &frames,
                &grid,
                &mut build_stages,
            )?)
        }
        BuildMethod::Stencil => PhotonMap::Routed(StencilRouting::new(gpu)?.build(
            &frames,
            &grid,
            config.stencil_block,
            config.feed(),
            &mut build_stages,
        )?),
    };
    gpu.finish();
    timings.add_folded("build map", &build_stages, t0);
    Ok(BuiltMap {
        map,
        trace,
        frames_traced: frames.frames,
        power_scale: frames.power_scale,
        grid,
        grid_fitted: scene.photon_map.grid_bounds.is_none(),
        build_stages,
        frames,
    })
}
