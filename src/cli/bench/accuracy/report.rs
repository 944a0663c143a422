//! What `bench accuracy` reports: each run, its method and its regions'
//! scores, as the JSON and the tables show them.

use serde::Serialize;

use photonmap::photon::{BuildMethod, GridKind};
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::{DifferentialsOptions, IgiOptions, Image, RadiosityOptions};

use crate::cli::bench::reference::ReferenceInfo;

/// A run's method, with that method's own options.
#[derive(Serialize, Clone, Debug)]
#[serde(tag = "method", rename_all = "kebab-case")]
pub enum RunMethod {
    /// The paper's one-shot kNN estimate of the global map.
    Paper,
    /// Final gather from the global map, `gather_rays` rays a pixel.
    FinalGather {
        gather_rays: u32,
    },
    Sppm {
        sppm_iterations: u32,
    },
    Igi(IgiOptions),
    Differentials(DifferentialsOptions),
    Radiosity(RadiosityOptions),
}

impl RunMethod {
    /// Its name in the JSON and the CSV.
    pub fn name(&self) -> &'static str {
        match self {
            RunMethod::Paper => "paper",
            RunMethod::FinalGather { .. } => "final-gather",
            RunMethod::Sppm { .. } => "sppm",
            RunMethod::Igi(_) => "igi",
            RunMethod::Differentials(_) => "differentials",
            RunMethod::Radiosity(_) => "radiosity",
        }
    }
}

/// One configuration's renders against the reference.
#[derive(Serialize, Clone, Debug)]
pub struct AccuracyRun {
    pub label: String,
    #[serde(flatten)]
    pub method: RunMethod,
    pub photons_stored: u32,
    pub k: u32,
    pub max_radius: f32,
    pub leak: LeakTest,
    pub shadow_rays: u32,
    pub build: BuildMethod,
    pub tile: u32,
    pub spp: u32,
    /// Adaptive sampling of the global light (its default threshold).
    pub adaptive: bool,
    /// The photon map's grid storage: uniform, or hashed (section 4.4).
    pub grid: GridKind,
    /// Wall seconds of one render (mean over the seeds).
    pub seconds: f64,
    /// RMSE of one render against the reference (mean over the seeds).
    pub rmse: f64,
    /// The part of it more seeds would not remove: the RMSE of the seeds'
    /// mean, less its noise and the reference's.
    pub bias_rmse: f64,
    /// The part they would: the RMS over pixels of one render's standard deviation.
    pub noise_rmse: f64,
    pub rel_mse: f64,
    pub ssim: f64,
    /// RMSE over the reference's mean (mean over the seeds): the relative
    /// error ground truth is quoted in.
    pub rel_rmse: f64,
    /// The seeds' mean image's mean over the reference's: 1 conserves energy.
    pub energy: f64,
    /// Energy and error by region (with `--regions` or `--region`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub regions: Vec<RegionScore>,
    pub on_pareto_front: bool,
}

#[derive(Serialize)]
pub struct AccuracyReport {
    /// The command that wrote it.
    pub command: String,
    pub scene: String,
    /// The reference's file.
    pub reference_file: String,
    /// Its JSON, when it is an SPPM reference.
    pub reference: Option<ReferenceInfo>,
    /// The mask's file, when only its pixels were compared.
    pub mask: Option<String>,
    /// Pixels compared.
    pub pixels_compared: usize,
    /// The regions' names and sizes, in the order of each run's `regions`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub regions: Vec<RegionSize>,
    pub renderer: String,
    pub seeds: u32,
    pub runs: Vec<AccuracyRun>,
    /// The front's fastest run within 10% of the least RMSE.
    pub recommended: String,
    /// `bias.png`'s full scale: a pixel is fully red (blue) where the scene
    /// defaults' mean over the seeds is this much brighter (darker) than the
    /// reference, in luminance. Half the reference's mean luminance.
    pub bias_map_scale: Option<f64>,
    /// `bias.png`, where the scene defaults' run is biased (when it ran).
    #[serde(skip)]
    pub bias_map: Option<Image>,
    /// With regions: every run's bias map, by label.
    #[serde(skip)]
    pub bias_maps: Vec<(String, Image)>,
}

#[derive(Serialize, Clone, Debug)]
pub struct RegionSize {
    pub name: String,
    /// Its pixels that are compared (inside the mask).
    pub pixels: usize,
}

/// One run on one region.
#[derive(Serialize, Clone, Debug)]
pub struct RegionScore {
    pub name: String,
    /// The seeds' mean image's mean over the reference's, on the region.
    pub energy: f64,
    /// The standard error of that ratio from the seeds' spread (the
    /// reference's own noise not included).
    pub energy_noise: f64,
    /// One render's RMSE over the reference's mean, on the region.
    pub rel_rmse: f64,
}
