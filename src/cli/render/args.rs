//! `photonmap render`'s arguments, and the method they choose (the one
//! place where switches that do not go together are refused).

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;
use photonmap::render::radiance_estimate::LeakTest;

use photonmap::image::check_writable;
use photonmap::provenance::Provenance;
use photonmap::render::sppm::SppmOptions;
use photonmap::render::{
    self, AdaptiveOptions, CausticPaths, FinalGatherOptions, IgiOptions, Image, PhotonMapOptions,
    PixelBounds, RadiosityOptions, RenderOptions, WithCausticMap, WithPhotons,
};
use photonmap::scene::Scene;

use crate::cli::args::{
    in_range, DifferentialsArgs, EstimateArgs, IgiArgs, LoadedScene, Method, PhotonMapArgs,
    RadiosityArgs, SceneArgs, SppmArgs, VcmArgs,
};

/// Render a scene to images: PNG (sRGB), EXR (linear float RGB, with the
/// provenance in its header) or PFM, chosen by each output's extension.
#[derive(Args)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// An output image, by extension: .png, .exr or .pfm (repeatable: -o a.png
    /// -o a.exr). All are written or none; each is checked before rendering.
    #[arg(short, long = "output", value_name = "FILE")]
    pub output: Vec<PathBuf>,
    /// Also write linear float RGB to this OpenEXR path (the same as -o X.exr).
    #[arg(long)]
    pub exr: Option<PathBuf>,
    /// Random seed: the same seed on the same driver gives the same image.
    #[arg(long, default_value_t = 1)]
    pub seed: u32,
    /// Eye samples per pixel: 1 (the paper) through the pixel centre; more are
    /// stratified, jittered and box-filtered, each with its own estimate (1..=1024).
    #[arg(long, default_value_t = 1, value_parser = in_range(1, 1024))]
    pub spp: u32,
    /// Image width in pixels (default: the scene's; 1..=16384).
    #[arg(long, value_parser = in_range(1, 16384))]
    pub width: Option<u32>,
    /// Image height in pixels (default: the scene's; 1..=16384).
    #[arg(long, value_parser = in_range(1, 16384))]
    pub height: Option<u32>,
    /// Render only this part of the frame, as fractions of its width and
    /// height from the top left: X0 X1 Y0 Y1, each in 0..=1 (pbrt's
    /// --cropwindow; each edge at the ceiling of its fraction, in pixels).
    /// The image is the crop; its EXR keeps the crop as its data window and
    /// the frame as its display window, and `merge --tiles` stitches tiles
    /// into the frame, bit for bit as one render makes it.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"], allow_negative_numbers = true, conflicts_with = "pixel_bounds")]
    pub crop_window: Option<Vec<f64>>,
    /// Render only pixels X0..X1 (columns) by Y0..Y1 (rows from the top),
    /// half-open (pbrt's --pixelbounds); as --crop-window otherwise.
    #[arg(long, num_args = 4, value_names = ["X0", "X1", "Y0", "Y1"])]
    pub pixel_bounds: Option<Vec<u32>>,
    /// No progress and no timing table on stderr.
    #[arg(long)]
    pub quiet: bool,
    /// Print a JSON report on stdout: provenance, options, outputs, timings.
    #[arg(long)]
    pub json: bool,
    /// List every pass that runs and every pass skipped, with why.
    #[arg(long)]
    pub explain: bool,
    /// Direct light and specular paths only: no photons, no radiance estimate.
    #[arg(long)]
    pub direct_only: bool,
    /// Global illumination: the paper's one-shot photon map, one of the
    /// other methods, or a progressive one (SPPM, VCM), which converges to
    /// the exact image.
    #[arg(long, value_enum, default_value_t = Method::Paper)]
    pub method: Method,
    /// Final gather (section 4.5): N cosine-distributed gather rays per pixel
    /// read a global photon map at their hits, and a caustic map is visualised
    /// at the first hits, instead of the one map visualised directly (1..=4096).
    #[arg(long, value_name = "N", value_parser = in_range(1, 4096), conflicts_with = "direct_only")]
    pub final_gather: Option<u32>,
    /// Final gather: k of the global map's estimate at each gather ray's hit
    /// (1..=4096). The default follows Jensen's practice of a small k for
    /// secondary lookups; it was not tuned against any reference.
    #[arg(long, default_value_t = 50, value_parser = in_range(1, 4096), requires = "final_gather")]
    pub gather_k: u32,
    /// Final gather: the leak test of the global map's estimates at the gather
    /// hits (none, as Jensen's secondary lookups; --leak-test sets the first hits').
    #[arg(long, value_enum, default_value_t = LeakTest::None, requires = "final_gather")]
    pub gather_leak_test: LeakTest,
    /// Adaptive sampling (section 4.5): compute global light on every 8th pixel,
    /// then at each finer level interpolate it where the coarser pixels around
    /// agree (same material, similar normal, light within --adaptive-threshold)
    /// and compute it elsewhere. Direct light stays at full resolution.
    #[arg(long, conflicts_with = "direct_only")]
    pub adaptive: bool,
    /// Adaptive sampling: interpolate where the corners' light spans at most
    /// this fraction of its mean (0 < F < 10; 0.1 a priori).
    #[arg(long, value_name = "F", default_value_t = 0.1, value_parser = threshold, requires = "adaptive")]
    pub adaptive_threshold: f32,
    #[command(flatten)]
    pub sppm: SppmArgs,
    #[command(flatten)]
    pub vcm: VcmArgs,
    #[command(flatten)]
    pub igi: IgiArgs,
    /// IGI and radiosity: the light their caustic map carries. all: every
    /// path onto a diffuse surface from a mirror or glass, including light a
    /// diffuse surface sends through them (L D+ S+ D), which VPLs and form
    /// factors cannot carry; from-lights: Jensen's caustic map, light
    /// straight from an emitter only (L S+ D).
    #[arg(long, value_enum, value_name = "PATHS")]
    pub caustic_paths: Option<CausticPaths>,
    /// IGI and radiosity: k of their caustic map's estimate (1..=4096).
    /// Default: the scene's photon_map.k, at most 16: a caustic is sharp,
    /// and the scene's k may be a global map's.
    #[arg(long, value_name = "K", value_parser = clap::value_parser!(u32).range(1..=4096))]
    pub caustic_k: Option<u32>,
    /// IGI and radiosity: build their caustic map on the scene's grid. By
    /// default its cells are (k / K)^(1/3) times finer on each axis (k the
    /// scene's, K the caustic map's), since the kNN-grid resolves nothing
    /// finer than a cell.
    #[arg(long)]
    pub caustic_scene_grid: bool,
    #[command(flatten)]
    pub differentials: DifferentialsArgs,
    #[command(flatten)]
    pub radiosity: RadiosityArgs,
    #[command(flatten)]
    pub photons: PhotonMapArgs,
    #[command(flatten)]
    pub estimate: EstimateArgs,
    /// Write the running estimate as numbered PNGs (and snapshots.json) into DIR.
    #[arg(long, value_name = "DIR")]
    pub snapshots: Option<PathBuf>,
    /// Send the image in progress to the tev HDR viewer listening at
    /// HOST:PORT (tev's TCP protocol; tev listens on 127.0.0.1:14158, which an
    /// ssh port forward can bring from another machine): the running estimate
    /// at most every 0.25 s, SPPM's iterations likewise, and every finished
    /// image, named "scene (pid)". A viewer that is not there, or goes away,
    /// never slows or stops the render.
    #[arg(long, value_name = "HOST:PORT", value_parser = super::display::parse_address)]
    pub display_server: Option<String>,
    /// Rewrite this EXR, atomically, with the image in progress (at most every
    /// 0.25 s) and last with the finished image; until then its header says
    /// `partial = true`.
    #[arg(long, value_name = "EXR", conflicts_with = "camera_path")]
    pub write_partial: Option<PathBuf>,
    /// What SIGINT or SIGTERM (Slurm's warning before a time limit) does:
    /// `stop` writes nothing; `write-partial` writes the eye samples (SPPM:
    /// the iterations) done so far to the EXR outputs, marked `partial =
    /// true` with their count in the header, so `merge --passes` can weigh
    /// them. A second signal ends the program at once.
    #[arg(long, value_enum, default_value_t = OnSignal::Stop, conflicts_with = "camera_path")]
    pub on_signal: OnSignal,
    /// Snapshot interval: seconds ("0.5s") or passes ("10").
    #[arg(long, default_value = "0.5s", value_parser = parse_every)]
    pub every: SnapshotEvery,
    /// Render a fly-through: a TOML of key cameras (and `frames = N`), all on one
    /// photon map, into --out as frame_NNNN.png.
    #[arg(long, value_name = "TOML", requires = "out", conflicts_with = "output")]
    pub camera_path: Option<PathBuf>,
    /// The folder for --camera-path frames.
    #[arg(long, value_name = "DIR", requires = "camera_path")]
    pub out: Option<PathBuf>,
    /// Also write the software reference (the paper's figure 7c: the same eye
    /// paths and photons, the estimate on the CPU by Jensen's kd-tree) to this PNG.
    #[arg(long, value_name = "PNG", conflicts_with = "direct_only")]
    pub reference_software: Option<PathBuf>,
}

/// What a render does when a signal stops it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OnSignal {
    Stop,
    WritePartial,
}

/// How often the running estimate is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SnapshotEvery {
    Seconds(f64),
    Passes(u32),
}

/// "0.5s" -> every half second of estimate; "10" -> every 10 passes.
pub(super) fn parse_every(text: &str) -> Result<SnapshotEvery, String> {
    let t = text.trim();
    if let Some(secs) = t.strip_suffix('s') {
        return match secs.parse::<f64>() {
            Ok(v) if v > 0.0 && v.is_finite() => Ok(SnapshotEvery::Seconds(v)),
            _ => Err(format!(
                "--every {text}: seconds must be a positive number, as in 0.5s"
            )),
        };
    }
    match t.parse::<u32>() {
        Ok(n) if n >= 1 => Ok(SnapshotEvery::Passes(n)),
        _ => Err(format!(
            "--every {text}: give seconds (0.5s) or a number of passes (10, at least 1)"
        )),
    }
}

/// `--adaptive-threshold`: a fraction in (0, 10).
pub(super) fn threshold(s: &str) -> Result<f32, String> {
    match s.trim().parse::<f32>() {
        Ok(v) if v > 0.0 && v < 10.0 => Ok(v),
        _ => Err(format!("{s}: the allowed range is 0 < F < 10")),
    }
}

/// An image format, by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    Png,
    Exr,
    Pfm,
}

impl Format {
    fn of(path: &Path) -> Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .unwrap_or("")
            .to_ascii_lowercase();
        Ok(match ext.as_str() {
            "png" => Format::Png,
            "exr" => Format::Exr,
            "pfm" => Format::Pfm,
            _ => bail!(
                "-o {}: the file name must end in .png, .exr or .pfm",
                path.display()
            ),
        })
    }

    pub(super) fn encode(self, image: &Image, provenance: &Provenance) -> Result<Vec<u8>> {
        Ok(match self {
            Format::Png => image.png_bytes()?,
            Format::Exr => image.exr_bytes_placed(
                &provenance.pairs(),
                provenance.origin(),
                (provenance.width, provenance.height),
            )?,
            Format::Pfm => image.pfm_bytes(),
        })
    }
}

/// Where the images go.
pub(super) enum Outputs {
    Images(Vec<(PathBuf, Format)>),
    /// A fly-through's frames (and any final-frame images).
    Frames(PathBuf, Vec<(PathBuf, Format)>),
}

impl Outputs {
    pub(super) fn images(&self) -> &[(PathBuf, Format)] {
        match self {
            Outputs::Images(v) | Outputs::Frames(_, v) => v,
        }
    }
}

/// What every render starts from, checked before any work: its outputs,
/// its scene and the options (the method's among them) for that scene.
pub(super) struct Start {
    pub outputs: Outputs,
    pub loaded: LoadedScene,
    pub options: RenderOptions,
}

impl RenderArgs {
    /// The method, the outputs and the scene (with a warning when it lies
    /// far from the origin), then the options for that scene.
    pub(super) fn start(&self) -> Result<Start> {
        let method = self.method()?;
        let outputs = self.outputs()?;
        let loaded = self.scene.load()?;
        warn_far_from_origin(&loaded.scene, self.quiet);
        let mut options = self.options(&loaded.scene, method);
        options.pixel_bounds = self.pixel_bounds_of(options.width, options.height)?;
        Ok(Start {
            outputs,
            loaded,
            options,
        })
    }

    /// `--crop-window` or `--pixel-bounds` in the frame's pixels, checked.
    fn pixel_bounds_of(&self, width: u32, height: u32) -> Result<Option<PixelBounds>> {
        let bounds = match (&self.crop_window, &self.pixel_bounds) {
            (Some(c), _) => {
                if let Some(f) = c.iter().find(|f| !(0.0..=1.0).contains(*f)) {
                    bail!("--crop-window {f}: each fraction must be in 0..=1");
                }
                let b = PixelBounds::of_crop_window([c[0], c[1], c[2], c[3]], width, height);
                if !b.fits(width, height) {
                    bail!(
                        "--crop-window {} {} {} {}: holds no pixel of the {width} x {height} frame (x0 < x1 and y0 < y1, after rounding up to pixels: {} {} {} {})",
                        c[0], c[1], c[2], c[3], b.x0, b.x1, b.y0, b.y1
                    );
                }
                b
            }
            (None, Some(p)) => {
                let b = PixelBounds {
                    x0: p[0],
                    x1: p[1],
                    y0: p[2],
                    y1: p[3],
                };
                if !b.fits(width, height) {
                    bail!(
                        "--pixel-bounds {} {} {} {}: need x0 < x1 <= {width} and y0 < y1 <= {height} (the {width} x {height} frame)",
                        b.x0, b.x1, b.y0, b.y1
                    );
                }
                b
            }
            (None, None) => return Ok(None),
        };
        Ok(Some(bounds))
    }

    /// Every output, checked before any work: a known extension, a folder
    /// that exists and takes a new file, not a folder itself.
    pub(super) fn outputs(&self) -> Result<Outputs> {
        if let Some(p) = &self.reference_software {
            crate::cli::check_output(p, "png", "--reference-software")?;
            check_writable(p)?;
        }
        if let Some(p) = &self.write_partial {
            if !p.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
                bail!(
                    "--write-partial {}: the file name must end in .exr",
                    p.display()
                );
            }
            if self.output.iter().chain(&self.exr).any(|o| o == p) {
                bail!(
                    "--write-partial {}: also an output; give the partial image a file of its own",
                    p.display()
                );
            }
            check_writable(p)?;
        }
        if self.on_signal == OnSignal::WritePartial
            && !self
                .output
                .iter()
                .chain(&self.exr)
                .any(|p| Format::of(p).ok() == Some(Format::Exr))
        {
            bail!("--on-signal write-partial: give an .exr output (-o X.exr): only an EXR's header can mark the image partial");
        }
        if let Some(dir) = &self.snapshots {
            if !dir.is_dir() {
                bail!("--snapshots {}: the folder does not exist", dir.display());
            }
        }
        let mut images = Vec::new();
        for p in self.output.iter().chain(&self.exr) {
            let format = Format::of(p)?;
            if self.exr.as_ref() == Some(p) && format != Format::Exr {
                bail!("--exr {}: the file name must end in .exr", p.display());
            }
            crate::cli::check_output(
                p,
                p.extension().and_then(|e| e.to_str()).unwrap_or(""),
                "-o",
            )?;
            check_writable(p)?;
            images.push((p.clone(), format));
        }
        match &self.out {
            Some(dir) => {
                if !dir.is_dir() {
                    bail!("--out {}: the folder does not exist", dir.display());
                }
                Ok(Outputs::Frames(dir.clone(), images))
            }
            None if images.is_empty() => {
                bail!("-o OUTPUT (.png, .exr or .pfm) is required (or --camera-path PATH.toml --out DIR)")
            }
            None => Ok(Outputs::Images(images)),
        }
    }

    /// The render's options for `scene`, with the method `self.method()` chose.
    pub(super) fn options(&self, scene: &Scene, method: render::Method) -> RenderOptions {
        let mut options = RenderOptions::for_scene(scene).with_method(method);
        options.seed = self.seed;
        options.spp = self.spp;
        options.width = self.width.unwrap_or(options.width);
        options.height = self.height.unwrap_or(options.height);
        options.pass_per_bounce = self.photons.faithful;
        options
    }

    /// The method with its options: the one place where switches that do
    /// not go together are refused.
    pub(super) fn method(&self) -> Result<render::Method> {
        if self.vcm.any_given() && self.method != Method::Vcm {
            bail!("--vcm-mode, --light-paths, --connections, --camera-continuation, --max-path-length, --merge-radius, --merge-start-pixels, --merge-alpha and --vcm-techniques are VCM's: add --method vcm");
        }
        if matches!(self.method, Method::Sppm | Method::Vcm) {
            self.check_sppm_switches()?;
        } else {
            self.check_method_switches()?;
        }
        let photons = (&self.photons).into();
        let estimate = (&self.estimate).into();
        let adaptive = self.adaptive.then_some(AdaptiveOptions {
            threshold: self.adaptive_threshold,
        });
        Ok(match self.method {
            _ if self.direct_only => render::Method::DirectOnly,
            Method::Paper => render::Method::PhotonMap(PhotonMapOptions {
                photons,
                estimate,
                final_gather: self.final_gather.map(|rays| FinalGatherOptions {
                    rays,
                    k: self.gather_k,
                    leak: self.gather_leak_test,
                }),
                adaptive,
            }),
            Method::Igi => render::Method::Igi(WithCausticMap {
                photons,
                estimate,
                method: IgiOptions {
                    caustic_paths: self.caustic_paths.unwrap_or_default(),
                    caustic_k: self.caustic_k,
                    caustic_scene_grid: self.caustic_scene_grid,
                    ..(&self.igi).into()
                },
            }),
            Method::Differentials => render::Method::Differentials(WithPhotons {
                photons,
                method: (&self.differentials).into(),
            }),
            Method::Radiosity => render::Method::Radiosity(WithCausticMap {
                photons,
                estimate,
                method: RadiosityOptions {
                    caustic_paths: self.caustic_paths.unwrap_or_default(),
                    caustic_k: self.caustic_k,
                    caustic_scene_grid: self.caustic_scene_grid,
                    ..(&self.radiosity).into()
                },
            }),
            Method::Vcm => render::Method::Vcm(self.vcm.options(&self.sppm)),
            Method::Sppm => render::Method::Sppm(WithPhotons {
                photons,
                method: SppmOptions {
                    adaptive,
                    leak: self.estimate.leak_test,
                    grid: self.photons.grid,
                    ..(&self.sppm).into()
                },
            }),
        })
    }

    /// `--method sppm` and `--method vcm` render one view with their own eye
    /// samples and photons; VCM takes no adaptive sampling.
    fn check_sppm_switches(&self) -> Result<()> {
        let name = if self.method == Method::Vcm {
            "vcm"
        } else {
            "sppm"
        };
        if self.method == Method::Vcm && (self.adaptive || self.sppm.adaptive_pilot.is_some()) {
            bail!("--method vcm has no adaptive sampling: drop --adaptive and --adaptive-pilot");
        }
        if self.camera_path.is_some()
            || self.direct_only
            || self.reference_software.is_some()
            || self.spp > 1
            || self.final_gather.is_some()
            || self.igi.any_given()
            || self.differentials.any_given()
            || self.radiosity.any_given()
            || self.caustic_paths.is_some()
            || self.caustic_k.is_some()
            || self.caustic_scene_grid
        {
            bail!("--method {name} renders one view with its own eye samples and photons: drop --camera-path, --direct-only, --reference-software, --spp, --final-gather, --caustic-paths, --caustic-k, --caustic-scene-grid, IGI's switches (--vpl-paths, --vpl-min-distance, --imperfect-visibility, --interleave, --downsample), photon differentials' (--smoothing, --caustic-smoothing, --footprint-max-radius, --leaf-size, --kernel, --footprint-coverage, --footprint-shape) and radiosity's (--elements, --substructure, --item-buffer, --max-shots, --convergence, --subdivide, --gradient, --form-factor, --shoot-caustics, --gather-rays)");
        }
        Ok(())
    }

    /// Refuses each method's switches without it, and what it cannot combine with.
    fn check_method_switches(&self) -> Result<()> {
        // Each method's own switches, and what its image (no one-map estimate)
        // cannot take.
        let one_map_only = self.final_gather.is_some()
            || self.adaptive
            || self.reference_software.is_some()
            || self.snapshots.is_some()
            || self.direct_only;
        let methods = [
            (
                Method::Igi,
                self.igi.any_given(),
                "--vpl-paths, --vpl-min-distance, --imperfect-visibility, --interleave, --downsample and --bias-compensation are IGI's: add --method igi",
                "--method igi has its own accelerations (--interleave, --downsample) and its image is no one-map estimate",
            ),
            (
                Method::Differentials,
                self.differentials.any_given(),
                "--smoothing, --caustic-smoothing, --footprint-max-radius, --leaf-size, --kernel, --footprint-coverage, --footprint-shape, --caustic-photons and --footprint-bounces are photon differentials': add --method differentials",
                "--method differentials replaces the kNN estimate with footprints",
            ),
            (
                Method::Radiosity,
                self.radiosity.any_given(),
                "--elements, --substructure, --item-buffer, --max-shots, --convergence, --subdivide, --gradient, --form-factor, --shoot-caustics and --gather-rays are radiosity's: add --method radiosity",
                "--method radiosity computes the diffuse interreflection itself (--gather-rays N gathers over its solution)",
            ),
        ];
        if (self.caustic_paths.is_some() || self.caustic_k.is_some() || self.caustic_scene_grid)
            && !matches!(self.method, Method::Igi | Method::Radiosity)
        {
            bail!("--caustic-paths, --caustic-k and --caustic-scene-grid choose the caustic map of IGI and radiosity: add --method igi or --method radiosity");
        }
        for (method, given, theirs, cannot) in methods {
            if self.method != method && given {
                bail!("{theirs}");
            }
            if self.method == method && one_map_only {
                bail!("{cannot}: drop --final-gather, --adaptive, --reference-software, --snapshots and --direct-only");
            }
        }
        if self.method == Method::Differentials {
            if let Some(s) = self
                .photons
                .build_switch_given()
                .or(self.estimate.switch_given())
            {
                bail!("{s} sets the kNN-grid's map or estimate, which --method differentials does not build: drop it");
            }
        }
        if self.sppm.adaptive_pilot.is_some() {
            bail!("--adaptive-pilot is adaptive SPPM's (--method sppm --adaptive); the one-shot estimate plans each eye sample's pyramid from its own coarse levels");
        }
        if (self.final_gather.is_some() || self.adaptive)
            && (self.snapshots.is_some() || self.reference_software.is_some())
        {
            // Snapshots show one estimate's running image, and the software
            // reference one map's: neither is the image final gather or the
            // pyramid composes.
            bail!("--snapshots and --reference-software show the one-map estimate: drop them with --final-gather or --adaptive");
        }
        Ok(())
    }
}

fn warn_far_from_origin(scene: &Scene, quiet: bool) {
    let ratio = scene.offset_ratio();
    if ratio > 1000.0 && !quiet {
        eprintln!(
            "warning: coordinates reach {ratio:.0} x the scene's size, even with the scene rebased to its centre; 32-bit floats resolve them only to ~{:.0e} of it, so fine detail (sharp caustics) may blur: bring the camera and the scene's parts closer together",
            ratio * f32::EPSILON
        );
    }
}
