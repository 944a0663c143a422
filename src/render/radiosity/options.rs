//! Radiosity's options, their checks, and what a solution reports.

use crate::error::Error;
use crate::gpu::Result;
use crate::render::photon_options::{CausticMap, CausticPaths, MAX_K};

/// How the radiosity solution runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RadiosityOptions {
    /// Elements per side of each tile.
    pub resolution: u32,
    /// Shooters per side of a shooting tile (substructuring; divides `resolution`).
    pub substructure: u32,
    /// Texels per side of each item buffer.
    pub item_buffer: u32,
    /// Shots at most.
    pub max_shots: u32,
    /// Converged once no tile holds this fraction of the emitted power unshot.
    pub convergence: f32,
    /// Quadtree depth at most (0: one uniform tile a patch).
    pub subdivide: u32,
    /// The split test's relative second difference (`discontinuity.frag`).
    pub gradient: f32,
    /// How a sub-element shooter's form factor is computed.
    pub form_factor: FormFactor,
    /// The caustic map's paths: all light onto x from a mirror or glass, or
    /// only light straight from an emitter (form factors stop at both).
    pub caustic_paths: CausticPaths,
    /// k of the caustic map's estimate; None: the scene's, at most
    /// `CAUSTIC_K`.
    pub caustic_k: Option<u32>,
    /// The caustic map on the scene's grid, not the refined one
    /// (`CausticMap::grid_resolution`).
    pub caustic_scene_grid: bool,
    /// Whether the caustic map's records are deposited into the elements
    /// before the first shot, so that light from a mirror or glass bounces
    /// on from the diffuse surface it reached (L S+ D D+).
    pub shoot_caustics: bool,
    /// Final gather over the solution: cosine-distributed rays a pixel that
    /// read the solution where they land, in place of reading it at the
    /// pixel (0: off).
    pub gather_rays: u32,
}

/// A shooter's form factor to a receiving element's centre.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum FormFactor {
    /// Lambert's exact point-to-polygon form factor to the sub-element's
    /// outline (a curved one's chord polygon: the same boundary, so the same
    /// form factor from wherever all of it is seen).
    Polygon,
    /// The chapter's oriented disc, A cos cos / (pi d^2 + A): exact on the
    /// disc's axis, short of the true value near the shooter.
    Disc,
}

impl Default for RadiosityOptions {
    /// 16 x 16 elements a tile (the chapter's leaf tiles), 4 x 4 shooters a
    /// tile, 256^2 item buffers, and a tile shoots while it holds 0.01% of
    /// the emitted power (a priori; the unshot total is reported). Tiles
    /// split once (depth 1) where the second difference exceeds a quarter of
    /// the local radiosity: against SPPM, depth 1 beat uniform tiles on
    /// CORNELL BOX and the mesh scene, and beat depth 2 on the mesh scene,
    /// which on CORNELL BOX took twice the solve for 0.3% less error (the book's radiosity page).
    fn default() -> Self {
        Self {
            resolution: 16,
            substructure: 4,
            item_buffer: 256,
            max_shots: 10_000,
            convergence: 1e-4,
            subdivide: 1,
            gradient: 0.25,
            form_factor: FormFactor::Polygon,
            caustic_paths: CausticPaths::All,
            caustic_k: None,
            caustic_scene_grid: false,
            shoot_caustics: true,
            gather_rays: 0,
        }
    }
}

impl RadiosityOptions {
    /// The caustic map's paths and k.
    pub fn caustic_map(&self) -> CausticMap {
        CausticMap {
            paths: self.caustic_paths,
            k: self.caustic_k,
            scene_grid: self.caustic_scene_grid,
        }
    }

    pub fn check(&self) -> Result<()> {
        if let Some(k) = self.caustic_k {
            Error::check_range("radiosity.caustic_k", k, 1..=MAX_K)?;
        }
        Error::check_range("radiosity.resolution", self.resolution, 2..=256)?;
        if self.substructure == 0 || !self.resolution.is_multiple_of(self.substructure) {
            return Err(Error::out_of_range(
                "radiosity.substructure",
                self.substructure,
                format!(
                    "give a divisor of the elements a side ({})",
                    self.resolution
                ),
            ));
        }
        if self.substructure > 8 {
            return Err(Error::out_of_range(
                "radiosity.substructure",
                self.substructure,
                "at most 8 (64 item buffers a shot)",
            ));
        }
        Error::check_range("radiosity.item_buffer", self.item_buffer, 16..=2048)?;
        if !(self.convergence > 0.0 && self.convergence < 1.0) {
            return Err(Error::out_of_range(
                "radiosity.convergence",
                self.convergence,
                "the allowed range is (0, 1)",
            ));
        }
        Error::check_range("radiosity.subdivide", self.subdivide, 0..=MAX_SUBDIVIDE)?;
        Error::check_range(
            "radiosity.gather_rays",
            self.gather_rays,
            0..=MAX_GATHER_RAYS,
        )?;
        Error::check_positive(
            "radiosity.gradient",
            self.gradient,
            "give a positive number",
        )
    }
}

/// Gather rays a pixel at most, as final gather's.
pub const MAX_GATHER_RAYS: u32 = 4096;

/// Quadtree depth at most (a tile at depth 6 is 1/64 of its patch a side).
pub const MAX_SUBDIVIDE: u32 = 6;

/// The split test's absolute floor, as a fraction of the scene's mean
/// irradiance (emitted power over receiving area): dim corners do not split
/// on differences far below what the image shows.
pub const SPLIT_FLOOR: f32 = 1e-2;

/// Adaptive subdivision tests a tile after a shot only when the shot brings
/// it this share of its radiosity power or more (ours; the chapter tests
/// every leaf after every reconstruction): after the first shots, which lay
/// down the shadows, most shots add little to most tiles, and testing every
/// tile every shot cost a mesh scene nine tenths of its solve.
pub const SPLIT_SHARE: f32 = 0.05;

/// The convergence of a solution: after each recorded shot, the unshot
/// power as a fraction of all emitted.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ConvergencePoint {
    pub shot: u32,
    pub seconds: f64,
    pub unshot_fraction: f64,
}

/// What a solution did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct RadiosityReport {
    pub patches: usize,
    /// Elements of live tiles at the end.
    pub elements: usize,
    pub element_resolution: u32,
    /// Live tiles at the end, and splits made.
    pub tiles: usize,
    pub splits: usize,
    /// Split tests (one occlusion query a tile) and the seconds they and the
    /// splits' passes took.
    pub split_tests: usize,
    pub subdivision_seconds: f64,
    /// True when a split found the atlas full (MAX_ATLAS_TEXELS).
    pub atlas_full: bool,
    /// The split test's absolute floor (SPLIT_FLOOR x the mean irradiance).
    pub split_floor: f32,
    pub shots: u32,
    /// The widest sub-element shooter shot (the largest distance between
    /// two points of its outline): a receiver nearer a shooter than this
    /// gets its mean radiosity, not the light beside it.
    pub largest_shooter: f32,
    pub converged: bool,
    pub unshot_fraction: f64,
    pub seconds: f64,
    pub convergence: Vec<ConvergencePoint>,
    /// Power deposited from the caustic map before the first shot (luminance,
    /// as a fraction of the emitted power), None when nothing was deposited.
    pub caustic_shot_fraction: Option<f64>,
}
