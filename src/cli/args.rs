//! Option groups shared by several subcommands, each turned into the
//! library's options by one conversion. Ranges are checked while parsing.

use clap::Args;
use photonmap::scene::import::ImportOptions;

use photonmap::photon::build::MAX_HASH_BUCKETS;
use photonmap::photon::differentials::FootprintShape;
use photonmap::photon::{BuildMethod, GridKind, PhotonConfig, VertexFeed};
use photonmap::render::differentials::{COVERAGE_SAMPLES, MAX_BOUNCES as DIFFERENTIALS_BOUNCES};
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::radiosity::FormFactor;
use photonmap::render::sppm::{DirectLighting, SppmOptions, SppmStart};
use photonmap::render::vcm::{VcmMode, VcmOptions};
use photonmap::render::{
    DifferentialsOptions, EstimateMode, EstimateOptions, IgiOptions, Kernel, RadiosityOptions,
};

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
    /// Photon-map build: counting sort (O(log n) passes; the bitonic
    /// build's map), bitonic sort + binary search (the paper's; what
    /// `--faithful` runs), or stencil routing.
    #[arg(long, value_enum, default_value_t = BuildMethod::Counting)]
    pub build: BuildMethod,
    /// Stencil routing: each cell holds m x m photons (1..=16).
    #[arg(long, default_value_t = 4, value_parser = in_range(1, 16))]
    pub stencil_m: u32,
    /// Stencil routing: how photons reach the vertex stage.
    #[arg(long, value_enum, default_value_t = VertexFeed::VertexFetch)]
    pub feed: VertexFeed,
    /// The paper's 2003 constraints: a texture of random numbers, read-back
    /// before routing, float addressing, no compaction, and the ray tracer's
    /// pass per bounce (else each eye path is one fused pass; the same image).
    #[arg(long)]
    pub faithful: bool,
    /// Scenes that store caustics only: emit photons in every direction
    /// instead of aiming them by projection maps (to compare).
    #[arg(long)]
    pub no_projection_map: bool,
    /// Trace all max_bounces photon bounces even when none is left alive.
    #[arg(long)]
    pub all_bounces: bool,
    /// How the grid stores its cells: one slot per cell (uniform), or a hash
    /// table keyed by the cell's address (hash, section 4.4: memory follows
    /// the photons, so grids up to 1024^3 fit).
    #[arg(long, value_enum)]
    pub grid: Option<GridKind>,
    /// Hash buckets of `--grid hash` (1..=16777216; default: the next power
    /// of two at or above the photons stored).
    #[arg(long, value_name = "N", value_parser = in_range(1, MAX_HASH_BUCKETS))]
    pub hash_buckets: Option<u32>,
}

impl PhotonMapArgs {
    /// The first switch given that only the kNN map's build reads.
    pub fn build_switch_given(&self) -> Option<&'static str> {
        [
            (self.build != BuildMethod::Counting, "--build"),
            (self.stencil_m != 4, "--stencil-m"),
            (self.feed != VertexFeed::VertexFetch, "--feed"),
            (self.grid.is_some(), "--grid"),
            (self.hash_buckets.is_some(), "--hash-buckets"),
        ]
        .into_iter()
        .find_map(|(given, name)| given.then_some(name))
    }
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
            grid: a.grid.unwrap_or_default(),
            hash_buckets: a.hash_buckets,
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
    /// range of cells opened (1..=100000).
    #[arg(long, default_value_t = DEFAULT_BUDGET, value_parser = in_range(1, 100_000))]
    pub budget: u32,
    /// Which photons in the search sphere may light a pixel: all (none, the
    /// paper's; light leaks through walls thinner than the radius), those near
    /// its tangent plane (disc), those nothing blocks (visibility, the
    /// default; SPPM's default is none), or both.
    #[arg(long, value_enum)]
    pub leak_test: Option<LeakTest>,
    /// Search as the paper does, opening every cell of each ring one by one,
    /// instead of skipping cells beyond the search radius and reading a row's
    /// cells as one range (the same image, bit for bit; only slower).
    #[arg(long)]
    pub paper_search: bool,
}

const DEFAULT_BUDGET: u32 = photonmap::render::radiance_estimate::DEFAULT_BUDGET;

impl EstimateArgs {
    /// The first switch given that only the kNN estimate reads.
    pub fn switch_given(&self) -> Option<&'static str> {
        [
            (self.tile != 16, "--tile"),
            (self.mask.is_some(), "--mask"),
            (self.budget != DEFAULT_BUDGET, "--budget"),
            (self.leak_test.is_some(), "--leak-test"),
            (self.paper_search, "--paper-search"),
        ]
        .into_iter()
        .find_map(|(given, name)| given.then_some(name))
    }
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
            leak: a.leak_test.unwrap_or(LeakTest::Visibility),
            cull: !a.paper_search,
            runs: !a.paper_search,
            ..EstimateOptions::default()
        }
    }
}

/// Which global-illumination method renders.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The paper's: one photon map, the kNN-grid radiance estimate.
    Paper,
    /// Stochastic progressive photon mapping: converges to the exact image.
    Sppm,
    /// Instant global illumination: virtual point lights for diffuse
    /// interreflection, a caustic photon map for caustics.
    Igi,
    /// Photon differentials: every photon a footprint, summed through a BVH
    /// photon map (no k-nearest search).
    Differentials,
    /// Progressive refinement radiosity: texels of an element atlas shoot
    /// and gather through item buffers; caustics from a caustic photon map.
    Radiosity,
    /// Vertex connection and merging: light and camera paths each
    /// iteration, each path taken by every technique that can make it (light
    /// tracing, path tracing, connections, photon merging) and weighted by
    /// multiple importance sampling; converges to the exact image.
    Vcm,
}

/// A positive finite number.
fn positive(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("{s}: give a positive number")),
    }
}

/// Pixel footprints: 0 (no bound) or a positive number, at most 1e6.
fn footprints(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if (0.0..=1e6).contains(&v) => Ok(v),
        _ => Err(format!(
            "{s}: give pixel footprints in 0..=1000000 (0: no bound)"
        )),
    }
}

/// A number strictly between 0 and 1.
fn fraction(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("{s}: the allowed range is (0, 1)")),
    }
}

/// A fraction in (0, 1].
fn unit_fraction(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v <= 1.0 => Ok(v),
        _ => Err(format!("{s}: the allowed range is (0, 1]")),
    }
}

/// Stochastic progressive photon mapping (`--method sppm`).
#[derive(Args, Clone, Debug)]
pub struct SppmArgs {
    /// SPPM: iterations (1..=1000000; default 64, or as many as --time allows).
    #[arg(long, value_parser = in_range(1, 1_000_000))]
    pub iterations: Option<u32>,
    /// SPPM: run for this many seconds (with --iterations too, whichever
    /// comes first).
    #[arg(long, value_name = "SECONDS", value_parser = positive)]
    pub time: Option<f64>,
    /// SPPM: the fraction of new photons kept, in (0, 1).
    #[arg(long, default_value_t = 0.7, value_parser = fraction)]
    pub alpha: f32,
    /// SPPM: photons emitted per iteration (64..=4194304).
    #[arg(long, default_value_t = 16384, value_parser = in_range(64, 1 << 22))]
    pub photons_per_iteration: u32,
    /// SPPM: every pixel's first radius (default: each pixel's own, from
    /// --start-pixels).
    #[arg(long, value_parser = positive)]
    pub radius: Option<f64>,
    /// SPPM: each pixel's first radius is at most P pixel footprints at its
    /// visible point (the width of its cone there); 0: no such bound
    /// (default 4). The first radius is the smallest of the scene's
    /// max_radius and both bounds.
    #[arg(long, value_name = "P", value_parser = footprints, conflicts_with = "radius")]
    pub start_pixels: Option<f64>,
    /// SPPM: each pixel's first radius holds at most the K nearest photons
    /// of the first iteration (progressive photon mapping's kNN start),
    /// 0..=65536; 0: no such bound (default 16).
    #[arg(long, value_name = "K", value_parser = in_range(0, 1 << 16), conflicts_with = "radius")]
    pub start_photons: Option<u32>,
    /// SPPM: photon bounces (1..=64); Russian roulette ends most far sooner.
    #[arg(long, default_value_t = 32, value_parser = in_range(1, 64))]
    pub photon_bounces: u32,
    /// SPPM: direct light by shadow rays at each visible point, or by photons.
    #[arg(long, value_enum, default_value_t = DirectLighting::ShadowRays)]
    pub sppm_direct: DirectLighting,
    /// SPPM: shadow rays per area light per iteration (1..=1024).
    #[arg(long, default_value_t = 1, value_parser = in_range(1, 1024))]
    pub sppm_shadow_rays: u32,
    /// SPPM with --adaptive: iterations at every pixel before the plan
    /// (1..iterations; default an eighth of --iterations, at least 1).
    #[arg(long, value_name = "N", value_parser = in_range(1, 1_000_000), requires = "adaptive")]
    pub adaptive_pilot: Option<u32>,
}

/// SPPM's iterations when neither --iterations nor --time is given.
pub const DEFAULT_SPPM_ITERATIONS: u32 = 64;
/// The most iterations a render runs: what `--time` alone allows.
pub const MAX_SPPM_ITERATIONS: u32 = 1_000_000;

impl SppmArgs {
    /// The iterations to run: as given; else as many as --time allows; else 64.
    pub fn iteration_limit(&self) -> u32 {
        match (self.iterations, self.time) {
            (Some(n), _) => n,
            (None, Some(_)) => MAX_SPPM_ITERATIONS,
            (None, None) => DEFAULT_SPPM_ITERATIONS,
        }
    }
}

impl From<&SppmArgs> for SppmOptions {
    fn from(a: &SppmArgs) -> Self {
        SppmOptions {
            iterations: a.iteration_limit(),
            seconds: a.time,
            alpha: a.alpha,
            photons_per_iteration: a.photons_per_iteration,
            initial_radius: a.radius.map(|r| r as f32),
            // Each flag replaces its own bound; 0 switches it off.
            start: SppmStart {
                pixels: match a.start_pixels {
                    Some(p) => (p > 0.0).then_some(p as f32),
                    None => SppmStart::DEFAULT.pixels,
                },
                photons: match a.start_photons {
                    Some(k) => (k > 0).then_some(k),
                    None => SppmStart::DEFAULT.photons,
                },
            },
            leak: None,
            grid: None,
            max_bounces: a.photon_bounces,
            direct: a.sppm_direct,
            shadow_rays: a.sppm_shadow_rays,
            adaptive: None,
            adaptive_pilot: a.adaptive_pilot,
        }
    }
}

/// Vertex connection and merging (`--method vcm`; its iterations and time
/// are --iterations and --time).
#[derive(Args, Clone, Debug, Default)]
pub struct VcmArgs {
    /// VCM: its techniques: pt (path tracing with next-event estimation),
    /// lt (light tracing), ppm (merging at the first diffuse vertex), bpt
    /// (connections, no merging), vcm (connections and merging; the default).
    #[arg(long, value_enum, value_name = "MODE")]
    pub vcm_mode: Option<VcmMode>,
    /// VCM: light paths traced an iteration (1..=4194304; default 16384).
    #[arg(long, value_name = "N", value_parser = in_range(1, 1 << 22))]
    pub light_paths: Option<u32>,
    /// VCM (bpt, vcm): light vertices each diffuse camera vertex connects
    /// to, drawn from all of the iteration's (1..=16; default 1).
    #[arg(long, value_name = "N", value_parser = in_range(1, 16))]
    pub connections: Option<u32>,
    /// VCM (bpt, vcm): camera paths go on past a diffuse vertex with this
    /// fraction of a light path's probability there, in (0, 1] (default
    /// 0.1); light tracing, connections and merging carry the rest, weighted.
    #[arg(long, value_name = "F", value_parser = unit_fraction)]
    pub camera_continuation: Option<f32>,
    /// VCM: the longest path, in segments (2..=64; default 32); Russian
    /// roulette ends most far sooner.
    #[arg(long, value_name = "N", value_parser = in_range(2, 64))]
    pub max_path_length: Option<u32>,
    /// VCM: the merging radius at the first iteration (default: 3 pixel
    /// footprints at the camera's look-at distance).
    #[arg(long, value_name = "R", value_parser = positive)]
    pub merge_radius: Option<f64>,
    /// VCM: the first merging radius in pixel footprints at the camera's
    /// look-at distance (> 0; default 3).
    #[arg(long, value_name = "P", value_parser = positive, conflicts_with = "merge_radius")]
    pub merge_start_pixels: Option<f64>,
    /// VCM: also write what each technique carried, one linear EXR each,
    /// into this folder (made if missing): lights_hit, next_event_estimation,
    /// connections, merging, light_tracing (they sum to the image).
    #[arg(long, value_name = "DIR")]
    pub vcm_techniques: Option<std::path::PathBuf>,
    /// VCM: the merging radius shrinks as i^((alpha - 1) / 2); alpha in
    /// (0, 1) (default 0.75).
    #[arg(long, value_name = "ALPHA", value_parser = fraction)]
    pub merge_alpha: Option<f32>,
}

impl VcmArgs {
    pub fn any_given(&self) -> bool {
        self.vcm_mode.is_some()
            || self.light_paths.is_some()
            || self.connections.is_some()
            || self.camera_continuation.is_some()
            || self.max_path_length.is_some()
            || self.merge_radius.is_some()
            || self.merge_start_pixels.is_some()
            || self.vcm_techniques.is_some()
            || self.merge_alpha.is_some()
    }

    /// The options, with the iterations and time of `sppm`'s --iterations
    /// and --time (which progressive methods share).
    pub fn options(&self, iterations: &SppmArgs) -> VcmOptions {
        let d = VcmOptions::default();
        VcmOptions {
            mode: self.vcm_mode.unwrap_or(d.mode),
            iterations: iterations.iteration_limit(),
            seconds: iterations.time,
            light_paths: self.light_paths.unwrap_or(d.light_paths),
            connections: self.connections.unwrap_or(d.connections),
            camera_continuation: self.camera_continuation.unwrap_or(d.camera_continuation),
            max_segments: self.max_path_length.unwrap_or(d.max_segments),
            initial_radius: self.merge_radius.map(|r| r as f32),
            start_pixels: self.merge_start_pixels.map_or(d.start_pixels, |p| p as f32),
            alpha: self.merge_alpha.unwrap_or(d.alpha),
        }
    }
}

/// Instant global illumination (`--method igi`).
#[derive(Args, Clone, Debug)]
pub struct IgiArgs {
    /// IGI: light paths traced for VPLs, one VPL at each diffuse hit (1..=1048576).
    #[arg(long, default_value_t = IgiOptions::default().vpl_paths, value_parser = in_range(1, 1 << 20))]
    pub vpl_paths: u32,
    /// IGI: bounces of a VPL path at most (1..=64; Russian roulette ends most far sooner).
    #[arg(long, default_value_t = 32, value_parser = in_range(1, 64))]
    pub vpl_bounces: u32,
    /// IGI: the geometry term's bounding distance m (VPLs nearer than 0.8 m
    /// light nothing; 0: unbounded). Default: the scene's photon_map.max_radius.
    #[arg(long, value_name = "M", value_parser = non_negative)]
    pub vpl_min_distance: Option<f64>,
    /// IGI: VPL shadow rays against primitive bounding boxes.
    #[arg(long)]
    pub imperfect_visibility: bool,
    /// IGI: interleaved sampling over N x N VPL subsets, merged by the
    /// discontinuity buffer (1..=8; 1: off, the paper's canonical IGI; 3: the
    /// paper's acceleration).
    #[arg(long, value_name = "N", default_value_t = IgiOptions::default().interleave, value_parser = in_range(1, 8))]
    pub interleave: u32,
    /// IGI: the VPL gather at one pixel per F x F block, joint-bilateral
    /// upsampled (1..=16; 1: off; the paper's 4).
    #[arg(long, value_name = "F", default_value_t = 1, value_parser = in_range(1, 16))]
    pub downsample: u32,
    /// IGI: bias compensation's gather rays a pixel, which add the light the
    /// bounded geometry term leaves out, read from a global photon map
    /// (0..=1024; 0: off).
    #[arg(long, value_name = "RAYS", default_value_t = IgiOptions::default().bias_compensation, value_parser = in_range(0, 1024))]
    pub bias_compensation: u32,
}

impl IgiArgs {
    /// Whether any IGI switch differs from its default.
    pub fn any_given(&self) -> bool {
        self.vpl_paths != IgiOptions::default().vpl_paths
            || self.vpl_bounces != 32
            || self.vpl_min_distance.is_some()
            || self.imperfect_visibility
            || self.interleave != IgiOptions::default().interleave
            || self.downsample != 1
            || self.bias_compensation != IgiOptions::default().bias_compensation
    }
}

impl From<&IgiArgs> for IgiOptions {
    fn from(a: &IgiArgs) -> Self {
        IgiOptions {
            vpl_paths: a.vpl_paths,
            vpl_bounces: a.vpl_bounces,
            min_distance: a.vpl_min_distance.map(|m| m as f32),
            imperfect_visibility: a.imperfect_visibility,
            interleave: a.interleave,
            downsample: a.downsample,
            bias_compensation: a.bias_compensation,
            ..IgiOptions::default()
        }
    }
}

/// Photon differentials' switches (`--method differentials`).
#[derive(Args, Clone, Debug)]
pub struct DifferentialsArgs {
    /// Differentials: the smoothing factor s of diffusely reflected photons'
    /// footprints (> 0), or auto: the one that aims the mean number of
    /// footprints at a first hit (k_PD) at the scene's k (a pilot map at
    /// s = 1; the summary line reports the k_PD reached).
    #[arg(long, value_name = "S", default_value = "auto", value_parser = auto_or_positive)]
    pub smoothing: AutoOr<f32>,
    /// Differentials: the factor of photons that have been only specular
    /// (caustics; > 0; the paper's 5).
    #[arg(long, value_name = "S", default_value_t = 5.0, value_parser = positive_f32)]
    pub caustic_smoothing: f32,
    /// Differentials: r_max, the longest footprint semi-axis (> 0). Default:
    /// the scene's photon_map.max_radius.
    #[arg(long, value_name = "R", value_parser = positive_f32)]
    pub footprint_max_radius: Option<f32>,
    /// Differentials: footprints a BVH leaf (1..=1024), or auto: the paper's
    /// threshold, total footprint area over surface area.
    #[arg(long, value_name = "T", default_value = "auto", value_parser = auto_or_leaf_size)]
    pub leaf_size: AutoOr<u32>,
    /// Differentials: the kernel over a footprint.
    #[arg(long, value_enum, default_value_t = Kernel::Constant)]
    pub kernel: Kernel,
    /// Differentials: probes of each footprint's share on its own surface
    /// (0..=256; 0: none, the whole ellipse counts). A footprint that
    /// overhangs an edge, a corner or an occluder then spreads all its power
    /// over the surface it is on instead of losing the overhang.
    #[arg(long, value_name = "N", default_value_t = COVERAGE_SAMPLES,
          value_parser = in_range(0, 256))]
    pub footprint_coverage: u32,
    /// Differentials: which query points a footprint holds. curved: those
    /// whose projection lies in its ellipse and which lie as near its plane
    /// as a surface curving to their normal would, so that a curved surface
    /// (a ball) stays in it; ellipsoid: the paper's thin ellipsoid, which
    /// lets a curved surface's points near its rim out and loses their
    /// light.
    #[arg(long, value_enum, default_value_t = FootprintShape::Curved)]
    pub footprint_shape: FootprintShape,
    /// Differentials: photons stored by a second trace aimed at mirrors and
    /// glass by projection maps, whose footprints carry the caustics (light
    /// from an emitter through mirrors or glass onto a diffuse surface)
    /// instead of the scene's photons' few caustic ones; 0: the paper's one
    /// map; auto: the scene's stored count where it has a mirror or glass
    /// and its map stores more than caustics, else 0.
    #[arg(long, value_name = "N", default_value = "auto", value_parser = auto_or_caustic_photons)]
    pub caustic_photons: AutoOr<u32>,
    /// Differentials: photon bounces at most (1..=64; Russian roulette ends
    /// most far sooner), in place of the scene's photon_map.max_bounces.
    #[arg(long, value_name = "N", default_value_t = DIFFERENTIALS_BOUNCES, value_parser = in_range(1, 64))]
    pub footprint_bounces: u32,
}

/// Progressive radiosity's switches (`--method radiosity`).
#[derive(Args, Clone, Debug)]
pub struct RadiosityArgs {
    /// Radiosity: elements per side of each tile, a leaf of a patch's
    /// quadtree (a patch is a side of a diffuse primitive) (2..=256).
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = in_range(2, 256))]
    pub elements: u32,
    /// Radiosity: shooters per side of a shooting tile, its elements merged
    /// S x S (substructuring; a divisor of --elements, 1..=8).
    #[arg(long, value_name = "S", default_value_t = 4, value_parser = in_range(1, 8))]
    pub substructure: u32,
    /// Radiosity: texels per side of each item buffer (16..=2048).
    #[arg(long, value_name = "N", default_value_t = 256, value_parser = in_range(16, 2048))]
    pub item_buffer: u32,
    /// Radiosity: shots at most (1..=1000000).
    #[arg(long, default_value_t = 10_000, value_parser = in_range(1, 1_000_000))]
    pub max_shots: u32,
    /// Radiosity: converged once no tile holds this fraction of the emitted
    /// power unshot (0 < F < 1).
    #[arg(long, value_name = "F", default_value_t = 1e-4, value_parser = open_fraction)]
    pub convergence: f32,
    /// Radiosity: adaptive subdivision's quadtree depth at most (0: one
    /// uniform tile a patch; 0..=6).
    #[arg(long, value_name = "D", default_value_t = RadiosityOptions::default().subdivide, value_parser = in_range(0, photonmap::render::radiosity::MAX_SUBDIVIDE))]
    pub subdivide: u32,
    /// Radiosity: a tile splits where the radiosity's second difference
    /// exceeds this fraction of the local radiosity (> 0).
    #[arg(long, value_name = "G", default_value_t = RadiosityOptions::default().gradient, value_parser = positive_f32)]
    pub gradient: f32,
    /// Radiosity: a shooter's form factor to an element: Lambert's exact
    /// point-to-polygon one, or the chapter's oriented disc.
    #[arg(long, value_enum, default_value_t = FormFactor::Polygon)]
    pub form_factor: FormFactor,
    /// Radiosity: deposit the caustic map's photons into the elements before
    /// the first shot, so that light from a mirror or glass bounces on from
    /// the diffuse surface it reached (L S+ D D+); false: shots start from
    /// the emitters alone.
    #[arg(long, value_name = "BOOL", default_value_t = true, action = clap::ArgAction::Set)]
    pub shoot_caustics: bool,
    /// Radiosity: final gather over the solution. N cosine-distributed rays
    /// a pixel read the solution where they land, so a pixel near a
    /// contact or a shadow's edge takes the light of the surfaces around it
    /// rather than its own element's (0: off, the solution read at the
    /// pixel; 0..=4096).
    #[arg(long, value_name = "N", default_value_t = 0, value_parser = in_range(0, photonmap::render::radiosity::MAX_GATHER_RAYS))]
    pub gather_rays: u32,
}

fn open_fraction(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v < 1.0 => Ok(v),
        _ => Err(format!("{s}: the allowed range is (0, 1)")),
    }
}

impl RadiosityArgs {
    pub fn any_given(&self) -> bool {
        let d = RadiosityOptions::default();
        self.elements != d.resolution
            || self.substructure != d.substructure
            || self.item_buffer != d.item_buffer
            || self.max_shots != d.max_shots
            || self.convergence != d.convergence
            || self.subdivide != d.subdivide
            || self.gradient != d.gradient
            || self.form_factor != d.form_factor
            || self.shoot_caustics != d.shoot_caustics
            || self.gather_rays != d.gather_rays
    }
}

impl From<&RadiosityArgs> for RadiosityOptions {
    fn from(a: &RadiosityArgs) -> Self {
        RadiosityOptions {
            resolution: a.elements,
            substructure: a.substructure,
            item_buffer: a.item_buffer,
            max_shots: a.max_shots,
            convergence: a.convergence,
            subdivide: a.subdivide,
            gradient: a.gradient,
            form_factor: a.form_factor,
            shoot_caustics: a.shoot_caustics,
            gather_rays: a.gather_rays,
            ..RadiosityOptions::default()
        }
    }
}

/// A value, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AutoOr<T> {
    Auto,
    Value(T),
}

impl<T: Copy> AutoOr<T> {
    pub fn value(self) -> Option<T> {
        match self {
            AutoOr::Auto => None,
            AutoOr::Value(v) => Some(v),
        }
    }
}

fn positive_f32(s: &str) -> Result<f32, String> {
    positive(s).map(|v| v as f32)
}

fn auto_or_positive(s: &str) -> Result<AutoOr<f32>, String> {
    if s.trim() == "auto" {
        return Ok(AutoOr::Auto);
    }
    positive(s)
        .map(|v| AutoOr::Value(v as f32))
        .map_err(|_| format!("{s}: give a positive number, or auto"))
}

fn auto_or_caustic_photons(s: &str) -> Result<AutoOr<u32>, String> {
    let max = photonmap::scene::defaults::MAX_PHOTONS_STORED;
    if s.trim() == "auto" {
        return Ok(AutoOr::Auto);
    }
    match s.trim().parse::<u32>() {
        Ok(v) if v == 0 || (64..=max).contains(&i64::from(v)) => Ok(AutoOr::Value(v)),
        _ => Err(format!(
            "{s}: the allowed range is 64..={max}, or 0 (no caustic footprint map), or auto"
        )),
    }
}

fn auto_or_leaf_size(s: &str) -> Result<AutoOr<u32>, String> {
    if s.trim() == "auto" {
        return Ok(AutoOr::Auto);
    }
    match s.trim().parse::<u32>() {
        Ok(v) if (1..=1024).contains(&v) => Ok(AutoOr::Value(v)),
        _ => Err(format!("{s}: the allowed range is 1..=1024, or auto")),
    }
}

impl DifferentialsArgs {
    /// Whether any differentials switch differs from its default.
    pub fn any_given(&self) -> bool {
        self.smoothing != AutoOr::Auto
            || self.caustic_smoothing != 5.0
            || self.footprint_max_radius.is_some()
            || self.leaf_size != AutoOr::Auto
            || self.kernel != Kernel::Constant
            || self.footprint_coverage != COVERAGE_SAMPLES
            || self.footprint_shape != FootprintShape::Curved
            || self.caustic_photons != AutoOr::Auto
            || self.footprint_bounces != DIFFERENTIALS_BOUNCES
    }
}

impl From<&DifferentialsArgs> for DifferentialsOptions {
    fn from(a: &DifferentialsArgs) -> Self {
        DifferentialsOptions {
            smoothing: a.smoothing.value(),
            caustic_smoothing: a.caustic_smoothing,
            max_radius: a.footprint_max_radius,
            leaf_size: a.leaf_size.value(),
            kernel: a.kernel,
            coverage_samples: a.footprint_coverage,
            footprint_shape: a.footprint_shape,
            caustic_photons: a.caustic_photons.value(),
            max_bounces: a.footprint_bounces,
        }
    }
}

/// A finite number of 0 or more.
fn non_negative(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v >= 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("{s}: give a number of 0 or more")),
    }
}

/// The scene a command renders, and overrides of its fields.
#[derive(Args, Clone, Debug)]
pub struct SceneArgs {
    /// Scene file (TOML; see the book's scene format), or the name of an embedded scene
    /// (`photonmap scenes` lists them: glass_ball, ring, cornell_box, ...).
    pub scene: std::path::PathBuf,
    /// Override a scene field by its path, validated like the file and
    /// recorded in every output: --set photon_map.k=64, -D camera.width=256,
    /// --set 'shape[1].radius=0.5' (repeatable; the value is TOML).
    /// For a Mitsuba scene (.xml), a KEY without `.` or `[` (other than
    /// `name`) sets the XML's `$KEY` and `<default name="KEY">`, as
    /// Mitsuba's -D does.
    #[arg(long = "set", short = 'D', value_name = "KEY=VALUE", value_parser = key_value)]
    pub set: Vec<(String, String)>,
    /// A pbrt or Mitsuba scene: map what photonmap cannot render (textures,
    /// rough and coated materials, media, environment lights...) to the
    /// nearest thing it can, printing one line for each, instead of refusing it.
    #[arg(long)]
    pub lenient: bool,
}

impl SceneArgs {
    /// The `--set` overrides for the TOML scene, and Mitsuba's `-D` values.
    pub fn split_overrides(&self) -> (Vec<(String, String)>, ImportOptions) {
        let mitsuba = photonmap::scene::import::format_of(&self.scene)
            == Some(photonmap::scene::import::Format::Mitsuba);
        let (defines, set): (Vec<_>, Vec<_>) = self
            .set
            .iter()
            .cloned()
            .partition(|(k, _)| mitsuba && k != "name" && !k.contains('.') && !k.contains('['));
        let opts = ImportOptions {
            lenient: self.lenient,
            defines,
        };
        (set, opts)
    }
}

pub fn key_value(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.trim().to_string())),
        _ => Err(format!("{s}: give KEY=VALUE, as in photon_map.k=64")),
    }
}

/// A loaded scene and what provenance needs of it.
pub struct LoadedScene {
    pub scene: photonmap::scene::Scene,
    pub provenance: photonmap::provenance::Provenance,
}

impl SceneArgs {
    pub fn load(&self) -> anyhow::Result<LoadedScene> {
        let (set, opts) = self.split_overrides();
        let (scene, text, notes) =
            photonmap::scene::embedded::load_imported(&self.scene, &set, &opts)?;
        for n in notes {
            eprintln!("note: {n}");
        }
        let mut provenance = photonmap::provenance::Provenance::program();
        provenance.scene = self.scene.display().to_string();
        provenance.scene_hash = format!("{:016x}", photonmap::provenance::fnv1a64(text.as_bytes()));
        provenance.overrides = self.set.iter().map(|(k, v)| format!("{k}={v}")).collect();
        Ok(LoadedScene { scene, provenance })
    }
}

/// The flag that sets a library option, by the option's field path: the
/// field's name in kebab case, where the flag does not say otherwise.
pub fn flag_of(option: &str) -> String {
    let renamed = match option {
        "igi.min_distance" => Some("--vpl-min-distance"),
        "differentials.max_radius" => Some("--footprint-max-radius"),
        "radiosity.resolution" => Some("--elements"),
        "sppm.initial_radius" => Some("--radius"),
        "sppm.start.photons" => Some("--start-photons"),
        "sppm.start.pixels" => Some("--start-pixels"),
        _ => None,
    };
    renamed.map_or_else(
        || {
            let field = option.rsplit('.').next().unwrap_or(option);
            format!("--{}", field.replace('_', "-"))
        },
        str::to_string,
    )
}
