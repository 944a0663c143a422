//! Option groups shared by several subcommands, each turned into the
//! library's options by one conversion. Ranges are checked while parsing.

use clap::Args;

use photonmap::photon::{BuildMethod, PhotonConfig, VertexFeed};
use photonmap::render::{EstimateMode, EstimateOptions};

/// A parser for a whole number in lo..=hi whose error names the range.
pub fn in_range(lo: u32, hi: u32) -> impl Fn(&str) -> Result<u32, String> + Clone + Send + Sync {
    move |s: &str| {
        let v: u32 = s
            .trim()
            .parse()
            .map_err(|_| format!("{s}: give a whole number; the allowed range is {lo}..={hi}"))?;
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(format!("{v}: the allowed range is {lo}..={hi}"))
        }
    }
}

/// How photons are traced and the map is built.
#[derive(Args, Clone, Debug)]
pub struct PhotonMapArgs {
    /// Photon-map build: bitonic sort + binary search, or stencil routing.
    #[arg(long, value_enum, default_value_t = BuildMethod::Bitonic)]
    pub build: BuildMethod,
    /// Stencil routing: each cell holds m x m photons (1..=16).
    #[arg(long, default_value_t = 4, value_parser = in_range(1, 16))]
    pub stencil_m: u32,
    /// Stencil routing: how photons reach the vertex stage.
    #[arg(long, value_enum, default_value_t = VertexFeed::VertexFetch)]
    pub feed: VertexFeed,
    /// The paper's 2003 constraints: a texture of random numbers, read-back
    /// before routing, float addressing, no compaction.
    #[arg(long)]
    pub faithful: bool,
    /// Scenes that store caustics only: emit photons in every direction
    /// instead of aiming them by projection maps (to compare).
    #[arg(long)]
    pub no_projection_map: bool,
    /// Trace all max_bounces photon bounces even when none is left alive.
    #[arg(long)]
    pub all_bounces: bool,
}

impl From<&PhotonMapArgs> for PhotonConfig {
    fn from(a: &PhotonMapArgs) -> Self {
        PhotonConfig {
            build: a.build,
            stencil_block: a.stencil_m,
            feed: a.feed,
            faithful: a.faithful,
            all_bounces: a.all_bounces,
            projection_maps: !a.no_projection_map,
        }
    }
}

/// How the radiance estimate is drawn.
#[derive(Args, Clone, Debug)]
pub struct EstimateArgs {
    /// Tiles of N x N pixels, each stopped by occlusion query; 0 draws full
    /// screen (0..=255: llvmpipe's largest point size).
    #[arg(long, default_value_t = 16, value_parser = in_range(0, 255))]
    pub tile: u32,
    /// Full screen behind a per-pixel stencil mask of finished pixels,
    /// refreshed every N passes (1..=100000).
    #[arg(long, value_name = "N", value_parser = in_range(1, 100_000))]
    pub mask: Option<u32>,
    /// Steps per pixel per pass, a step being one photon examined or one
    /// cell moved (1..=100000).
    #[arg(long, default_value_t = 64, value_parser = in_range(1, 100_000))]
    pub budget: u32,
}

impl From<&EstimateArgs> for EstimateOptions {
    fn from(a: &EstimateArgs) -> Self {
        EstimateOptions {
            mode: match (a.mask, a.tile) {
                (Some(every), _) => EstimateMode::Masked { every },
                (None, 0) => EstimateMode::FullScreen,
                (None, tile) => EstimateMode::Tiled { tile },
            },
            budget: a.budget,
            ..EstimateOptions::default()
        }
    }
}
