//! What a `tables` run reports (results.json, and the tables Markdown is
//! made from): Table 1's cells and totals, section 3.3's rows, the pass
//! counts, figure 8's snapshots and Table 2's instruction counts.

use serde::Serialize;

use photonmap::bench::build::BuildBenchRow;
use photonmap::photon::BuildMethod;

/// Steps per pixel per pass of figure 8's render.
pub(super) const FIGURE8_BUDGET: u32 = 16;

pub(super) const STAGES: [&str; 4] = [
    "trace photons",
    "build map",
    "trace rays",
    "radiance estimate",
];

#[derive(Serialize)]
pub struct Table1Cell {
    pub scene: String,
    pub build: BuildMethod,
    pub stage: String,
    pub wall_seconds: Vec<f64>,
    pub median_wall_seconds: f64,
    pub min_wall_seconds: f64,
    pub max_wall_seconds: f64,
    pub median_gpu_seconds: f64,
    pub paper_seconds: f64,
    pub ratio_to_paper: f64,
    pub at_or_below_paper: bool,
}

#[derive(Serialize)]
pub struct Table1Total {
    pub scene: String,
    pub build: BuildMethod,
    pub median_seconds: f64,
    pub paper_seconds: f64,
    pub ratio_to_paper: f64,
    /// The target: at most a quarter of the paper's total.
    pub at_most_a_quarter: bool,
}

#[derive(Serialize)]
pub struct ConvergenceRow {
    pub scene: String,
    pub mode: String,
    pub wall_seconds: f64,
    pub passes: u32,
    pub tile_draws: u64,
}

#[derive(Serialize)]
pub struct Figure8 {
    pub file: String,
    pub snapshots: Vec<(String, f64, f64)>,
    pub full_convergence_seconds: f64,
    pub visual_convergence_seconds: f64,
    pub criterion: String,
}

#[derive(Serialize)]
pub struct KernelCount {
    pub kernel: String,
    pub instructions: usize,
    pub texture_fetches: usize,
    pub address_arithmetic: usize,
    pub packing: usize,
    pub paper: [usize; 4],
}

#[derive(Serialize)]
pub struct TablesReport {
    pub renderer: String,
    pub gl_version: String,
    pub cores: usize,
    pub quick: bool,
    pub faithful: bool,
    pub stencil_m: u32,
    pub table1_only: bool,
    pub image_scale: String,
    pub runs: u32,
    pub command: String,
    pub table1: Vec<Table1Cell>,
    pub totals: Vec<Table1Total>,
    pub convergence: Vec<ConvergenceRow>,
    pub passes: Vec<BuildBenchRow>,
    pub figure7: String,
    pub figure8: Option<Figure8>,
    pub table2: Result<Vec<KernelCount>, String>,
}
