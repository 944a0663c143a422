//! `bench mitsuba`'s options.

use std::path::PathBuf;

use clap::Args;

use photonmap::bench::regions::Rectangle;

use crate::cli::args::in_range;
use crate::cli::bench::output::BenchOutput;

/// A progressive method `bench mitsuba` races.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum ProgressiveMethod {
    /// Stochastic progressive photon mapping.
    Sppm,
    /// Vertex connection and merging.
    Vcm,
}

impl std::fmt::Display for ProgressiveMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ProgressiveMethod::Sppm => "sppm",
            ProgressiveMethod::Vcm => "vcm",
        })
    }
}

#[derive(Args)]
pub struct MitsubaBenchArgs {
    /// Scene file or embedded name.
    #[arg(long)]
    pub scene: PathBuf,
    /// The image every render is compared with (linear EXR; default
    /// reference_images/truth/<scene>.exr where it exists, else the scene's
    /// SPPM reference as `bench accuracy` finds it). Everything renders at
    /// its size, which must be the scene's divided by a whole number.
    #[arg(long, value_name = "EXR", conflicts_with = "mitsuba_reference")]
    pub reference: Option<PathBuf>,
    /// For scenes without committed truth: the reference is Mitsuba's path
    /// tracer, two independent runs of this many seconds each, averaged
    /// (`reference.exr` in --out); their difference gives its noise. Path
    /// tracing converges to the exact image, but slowly where light reaches
    /// diffuse surfaces through mirrors or glass, and never from a point
    /// light through them: use it for scenes it handles.
    #[arg(long, value_name = "SECONDS", value_parser = budget_seconds)]
    pub mitsuba_reference: Option<f64>,
    /// With --mitsuba-reference: render at the scene's size divided by this
    /// (1..=16; the size must divide).
    #[arg(long, default_value_t = 2, value_parser = in_range(1, 16), requires = "mitsuba_reference")]
    pub scale: u32,
    /// Only pixels where this PNG (the reference's size) is bright count
    /// (default with the default truth: its interior mask,
    /// reference_images/truth/<scene>_interior_mask.png; otherwise every
    /// pixel).
    #[arg(long, value_name = "PNG")]
    pub mask: Option<PathBuf>,
    /// A rectangle in which every image's energy is reported against the
    /// reference's: NAME=X0:X1:Y0:Y1, columns X0..X1 and rows Y0..Y1 of the
    /// reference's pixels, row 0 at the top, ends excluded, less what the
    /// mask leaves out. The table goes to regions.md. Repeat it for more.
    #[arg(long, value_name = "NAME=X0:X1:Y0:Y1", value_parser = rectangle)]
    pub region: Vec<Rectangle>,
    /// Wall-time budgets in seconds (e.g. 30,60,120): each of --methods at
    /// its defaults and each Mitsuba integrator render for each; the longest
    /// also records the convergence curves.
    #[arg(long, value_delimiter = ',', value_parser = budget_seconds)]
    pub seconds: Vec<f64>,
    /// photonmap's one-map render at its defaults with this many eye
    /// samples per pixel (1..=1024), one render each; --methods and Mitsuba
    /// get each render's wall time (default 1 without --seconds, none with it).
    #[arg(long, value_delimiter = ',', value_parser = in_range(1, 1024))]
    pub spp: Vec<u32>,
    /// photonmap's progressive methods, each at its defaults, raced for
    /// each --seconds budget: sppm, vcm.
    #[arg(long, value_delimiter = ',', default_values_t = [ProgressiveMethod::Sppm, ProgressiveMethod::Vcm])]
    pub methods: Vec<ProgressiveMethod>,
    /// Mitsuba's integrators: path (path tracing with next-event estimation),
    /// ptracer (light tracing, which finds a point light's caustic).
    #[arg(long, value_delimiter = ',', default_values_t = ["path".to_string(), "ptracer".to_string()])]
    pub integrators: Vec<String>,
    /// Mitsuba's variant.
    #[arg(long, default_value = "llvm_ad_rgb")]
    pub variant: String,
    /// The Python that imports mitsuba.
    #[arg(long, default_value = "python3")]
    pub python: String,
    /// Mitsuba's longest path (max_depth: -1, Mitsuba's default, leaves
    /// paths to Russian roulette; else 1..=1024).
    #[arg(long, default_value_t = -1, allow_negative_numbers = true, value_parser = max_depth)]
    pub max_depth: i32,
    /// Folder for the export, the script, each image, mitsuba.json and
    /// convergence.svg (default photonmap-out/mitsuba/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// Mitsuba's max_depth: -1 (unbounded) or 1..=1024.
fn max_depth(s: &str) -> Result<i32, String> {
    match s.trim().parse::<i32>() {
        Ok(v) if v == -1 || (1..=1024).contains(&v) => Ok(v),
        _ => Err(format!("{s}: give -1 (no limit) or a depth in 1..=1024")),
    }
}

/// `--region`'s NAME=X0:X1:Y0:Y1.
fn rectangle(s: &str) -> Result<Rectangle, String> {
    s.parse()
}

/// A budget: a positive number of seconds, at most a day.
fn budget_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 86_400.0 => Ok(v),
        _ => Err(format!("{s}: give seconds above 0 (at most 86400)")),
    }
}
