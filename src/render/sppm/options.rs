//! SPPM's options: iterations or time, the first radius's bounds, alpha,
//! where direct light comes from, the leak test and adaptive sampling.

use crate::photon::GridKind;
use crate::render::adaptive::AdaptiveOptions;
use crate::render::radiance_estimate::LeakTest;

/// Where direct light comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum DirectLighting {
    /// Shadow rays at each visible point (the paper's split; exact for point lights).
    ShadowRays,
    /// Photons stored at their first hit too, and no shadow rays.
    Photons,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct SppmOptions {
    /// Iterations to run (the render also stops at `seconds`, if given).
    pub iterations: u32,
    pub seconds: Option<f64>,
    /// The fraction of new photons kept (Hachisuka and Jensen's alpha).
    pub alpha: f32,
    /// Photons emitted per iteration (the same every iteration).
    pub photons_per_iteration: u32,
    /// First radius of every pixel; None: each pixel's own, as `start` says.
    pub initial_radius: Option<f32>,
    /// How each pixel's first radius is chosen when `initial_radius` is None.
    pub start: SppmStart,
    /// The leak tests of the gather (None: `DEFAULT_SPPM_LEAK`).
    pub leak: Option<LeakTest>,
    /// The grid's storage (None: hashed, or uniform under `--faithful`).
    pub grid: Option<GridKind>,
    /// Photon bounces (Russian roulette ends most photons long before).
    pub max_bounces: u32,
    pub direct: DirectLighting,
    /// Shadow rays per area light per iteration.
    pub shadow_rays: u32,
    /// Adaptive sampling (`sppm_adaptive.rs`): after the pilot, the gather
    /// runs only where the pyramid's plan computes.
    pub adaptive: Option<AdaptiveOptions>,
    /// Iterations at every pixel before the plan (default: an eighth).
    pub adaptive_pilot: Option<u32>,
}

impl Default for SppmOptions {
    fn default() -> Self {
        Self {
            iterations: 64,
            seconds: None,
            alpha: 0.7,
            photons_per_iteration: 1 << 14,
            initial_radius: None,
            start: SppmStart::DEFAULT,
            leak: None,
            grid: None,
            max_bounces: 32,
            direct: DirectLighting::ShadowRays,
            shadow_rays: 1,
            adaptive: None,
            adaptive_pilot: None,
        }
    }
}

/// How each pixel's first radius is chosen (at the first iteration, at its
/// visible point; `glsl/render/sppm_start.frag`): the smallest of the scene's
/// max_radius and the bounds given.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct SppmStart {
    /// At most this many pixel footprints: the width of a pixel's cone at
    /// the point.
    pub pixels: Option<f32>,
    /// At most the radius that holds this many of the first iteration's
    /// photons (progressive photon mapping's kNN start).
    pub photons: Option<u32>,
}

impl SppmStart {
    pub const DEFAULT: SppmStart = SppmStart {
        pixels: Some(DEFAULT_START_PIXELS),
        photons: DEFAULT_START_PHOTONS,
    };
}

/// The first radius in pixel footprints by default. Chosen against the
/// independent truth at equal time (the book, "The truth: SPPM").
pub const DEFAULT_START_PIXELS: f32 = 4.0;

/// The kNN bound on the first radius by default: bright caustics start
/// smaller than 4 footprints. Chosen against the independent truth at equal
/// iterations (docs, methods/sppm.md): 16 against no bound gives RING 0.034
/// against 0.048 relative RMSE, GLASS BALL 0.051-0.053 against 0.055-0.056,
/// CORNELL BOX 0.051-0.052 against 0.051-0.052.
pub const DEFAULT_START_PHOTONS: Option<u32> = Some(16);

/// The gather's leak test by default: none. The leak vanishes as the radii
/// shrink, and the visibility test's shadow ray per photon cost more error
/// at equal time than it removed (the book, "The truth: SPPM").
pub const DEFAULT_SPPM_LEAK: LeakTest = LeakTest::None;
