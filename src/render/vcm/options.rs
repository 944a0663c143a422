//! Vertex connection and merging's options.

use crate::layout::{VCM_MODE_BPT, VCM_MODE_LT, VCM_MODE_PPM, VCM_MODE_PT, VCM_MODE_VCM};

/// Which techniques make the image (SmallVCM's algorithms, for testing and
/// teaching; `Vcm` is the renderer's).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum VcmMode {
    /// Path tracing: next-event estimation and paths that hit a light,
    /// weighted between the two; Russian roulette from the fourth hit on.
    Pt,
    /// Light tracing: every light vertex connected to the camera (and
    /// lights seen directly or through mirrors and glass).
    Lt,
    /// Progressive photon mapping: merging at the camera path's first diffuse
    /// vertex, unweighted (biased; consistent as the radius shrinks).
    Ppm,
    /// Bidirectional path tracing: next-event estimation, connections to
    /// light vertices drawn from all of the iteration's and light tracing;
    /// no merging.
    Bpt,
    /// Vertex connection and merging: the techniques of bpt and merging at
    /// every diffuse camera vertex.
    #[default]
    Vcm,
}

impl VcmMode {
    /// Its code in `glsl/vcm/` (`VCM_MODE`, compiled into the programs).
    pub fn code(self) -> u32 {
        match self {
            VcmMode::Pt => VCM_MODE_PT,
            VcmMode::Lt => VCM_MODE_LT,
            VcmMode::Ppm => VCM_MODE_PPM,
            VcmMode::Bpt => VCM_MODE_BPT,
            VcmMode::Vcm => VCM_MODE_VCM,
        }
    }

    /// Whether its light paths are traced (all but path tracing).
    pub fn traces_light_paths(self) -> bool {
        self != VcmMode::Pt
    }

    /// Whether it merges (builds a map of the light vertices).
    pub fn merges(self) -> bool {
        matches!(self, VcmMode::Ppm | VcmMode::Vcm)
    }

    /// Whether it connects light vertices to the camera (light tracing).
    pub fn splats(self) -> bool {
        matches!(self, VcmMode::Lt | VcmMode::Bpt | VcmMode::Vcm)
    }

    /// Whether it connects camera and light vertices (and weights the
    /// techniques by their pdfs).
    pub fn connects(self) -> bool {
        matches!(self, VcmMode::Bpt | VcmMode::Vcm)
    }

    pub fn name(self) -> &'static str {
        match self {
            VcmMode::Pt => "pt",
            VcmMode::Lt => "lt",
            VcmMode::Ppm => "ppm",
            VcmMode::Bpt => "bpt",
            VcmMode::Vcm => "vcm",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct VcmOptions {
    pub mode: VcmMode,
    /// Iterations at most.
    pub iterations: u32,
    /// Stop after this many seconds (the iterations begun finish).
    pub seconds: Option<f64>,
    /// Light subpaths an iteration traces (N).
    pub light_paths: u32,
    /// Light vertices each diffuse camera vertex connects to, drawn
    /// uniformly from all of the iteration's (the light vertex cache).
    pub connections: u32,
    /// With connections (bpt, vcm): a camera path goes on past a diffuse
    /// vertex with this fraction, in (0, 1], of the probability a light path
    /// goes on with there. Light tracing, connections and merging then carry
    /// more of the light; the MIS weights count each subpath's own Russian
    /// roulette, so the image converges to the same answer.
    pub camera_continuation: f32,
    /// The longest path, in segments (the eye ray is one).
    pub max_segments: u32,
    /// The merging radius of iteration 1 (default: `start_pixels` pixel
    /// footprints at the camera's look-at distance).
    pub initial_radius: Option<f32>,
    /// Pixel footprints the default first radius spans.
    pub start_pixels: f32,
    /// The radius shrinks as r_i = r_1 i^((alpha - 1) / 2).
    pub alpha: f32,
}

impl VcmOptions {
    /// The camera paths' continuation fraction the mode runs with: path
    /// tracing alone needs its paths whole; light tracing and ppm end them
    /// at the first diffuse vertex anyway.
    pub fn camera_continuation_in_use(&self) -> f32 {
        if self.mode.connects() {
            self.camera_continuation
        } else {
            1.0
        }
    }

    pub const DEFAULT_LIGHT_PATHS: u32 = 1 << 14;
    pub const DEFAULT_CONNECTIONS: u32 = 1;
    pub const DEFAULT_CAMERA_CONTINUATION: f32 = 0.1;
    pub const DEFAULT_MAX_SEGMENTS: u32 = 32;
    pub const DEFAULT_ALPHA: f32 = 0.75;
    pub const DEFAULT_START_PIXELS: f32 = 3.0;
}

impl Default for VcmOptions {
    fn default() -> Self {
        Self {
            mode: VcmMode::Vcm,
            iterations: 64,
            seconds: None,
            light_paths: Self::DEFAULT_LIGHT_PATHS,
            connections: Self::DEFAULT_CONNECTIONS,
            camera_continuation: Self::DEFAULT_CAMERA_CONTINUATION,
            max_segments: Self::DEFAULT_MAX_SEGMENTS,
            initial_radius: None,
            start_pixels: Self::DEFAULT_START_PIXELS,
            alpha: Self::DEFAULT_ALPHA,
        }
    }
}
