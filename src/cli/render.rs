//! `photonmap render`: one image (any number of PNG, EXR and PFM files), or a
//! fly-through of frames on one photon map.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use clap::Args;
use photonmap::render::radiance_estimate::LeakTest;

use photonmap::gpu::Platform;
use photonmap::image::{check_writable, write_all_atomically, write_atomically};
use photonmap::provenance::Provenance;
use photonmap::render::sppm::SppmOptions;
use photonmap::render::{
    self, AdaptiveOptions, EstimatePass, FinalGatherOptions, Image, PassPlan, PhotonMapOptions,
    Progress, RenderObserver, RenderOptions, StopReason, WithCausticMap, WithPhotons,
};
use photonmap::scene::Scene;

use super::args::{
    in_range, DifferentialsArgs, EstimateArgs, IgiArgs, Method, PhotonMapArgs, RadiosityArgs,
    SceneArgs, SppmArgs,
};
use super::progress::{ProgressReport, Work};

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
    /// Global illumination: the paper's one-shot photon map, or stochastic
    /// progressive photon mapping (which converges to the exact image).
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
    pub igi: IgiArgs,
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

/// How often the running estimate is written.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SnapshotEvery {
    Seconds(f64),
    Passes(u32),
}

/// "0.5s" -> every half second of estimate; "10" -> every 10 passes.
fn parse_every(text: &str) -> Result<SnapshotEvery, String> {
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
fn threshold(s: &str) -> Result<f32, String> {
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

    fn encode(self, image: &Image, provenance: &Provenance) -> Result<Vec<u8>> {
        Ok(match self {
            Format::Png => image.png_bytes()?,
            Format::Exr => image.exr_bytes_with(&provenance.pairs())?,
            Format::Pfm => image.pfm_bytes(),
        })
    }
}

/// Where the images go.
enum Outputs {
    Images(Vec<(PathBuf, Format)>),
    /// A fly-through's frames (and any final-frame images).
    Frames(PathBuf, Vec<(PathBuf, Format)>),
}

impl Outputs {
    fn images(&self) -> &[(PathBuf, Format)] {
        match self {
            Outputs::Images(v) | Outputs::Frames(_, v) => v,
        }
    }
}

impl RenderArgs {
    /// Every output, checked before any work: a known extension, a folder
    /// that exists and takes a new file, not a folder itself.
    fn outputs(&self) -> Result<Outputs> {
        if let Some(p) = &self.reference_software {
            super::check_output(p, "png", "--reference-software")?;
            check_writable(p)?;
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
            super::check_output(
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

    fn options(&self, scene: &Scene) -> Result<RenderOptions> {
        let mut options = RenderOptions::for_scene(scene).with_method(self.method()?);
        options.seed = self.seed;
        options.spp = self.spp;
        options.width = self.width.unwrap_or(options.width);
        options.height = self.height.unwrap_or(options.height);
        Ok(options)
    }

    /// The method with its options: the one place where switches that do
    /// not go together are refused.
    fn method(&self) -> Result<render::Method> {
        if self.method == Method::Sppm {
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
                method: (&self.igi).into(),
            }),
            Method::Differentials => render::Method::Differentials(WithPhotons {
                photons,
                method: (&self.differentials).into(),
            }),
            Method::Radiosity => render::Method::Radiosity(WithCausticMap {
                photons,
                estimate,
                method: (&self.radiosity).into(),
            }),
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

    /// `--method sppm` renders one view with its own eye samples and photons.
    fn check_sppm_switches(&self) -> Result<()> {
        if self.camera_path.is_some()
            || self.direct_only
            || self.reference_software.is_some()
            || self.spp > 1
            || self.final_gather.is_some()
            || self.igi.any_given()
            || self.differentials.any_given()
            || self.radiosity.any_given()
        {
            bail!("--method sppm renders one view with its own eye samples and photons: drop --camera-path, --direct-only, --reference-software, --spp, --final-gather, IGI's switches (--vpl-paths, --vpl-min-distance, --imperfect-visibility, --interleave, --downsample), photon differentials' (--smoothing, --caustic-smoothing, --footprint-max-radius, --leaf-size, --kernel) and radiosity's (--elements, --substructure, --item-buffer, --max-shots, --convergence, --subdivide, --gradient, --form-factor)");
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
                "--vpl-paths, --vpl-min-distance, --imperfect-visibility, --interleave and --downsample are IGI's: add --method igi",
                "--method igi has its own accelerations (--interleave, --downsample) and its image is no one-map estimate",
            ),
            (
                Method::Differentials,
                self.differentials.any_given(),
                "--smoothing, --caustic-smoothing, --footprint-max-radius, --leaf-size and --kernel are photon differentials': add --method differentials",
                "--method differentials replaces the kNN estimate with footprints",
            ),
            (
                Method::Radiosity,
                self.radiosity.any_given(),
                "--elements, --substructure, --item-buffer, --max-shots, --convergence, --subdivide, --gradient and --form-factor are radiosity's: add --method radiosity",
                "--method radiosity computes the diffuse interreflection itself",
            ),
        ];
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

/// What `--json` prints: provenance, the outputs and the run's figures.
#[derive(serde::Serialize)]
struct Report<'a> {
    provenance: &'a Provenance,
    outputs: Vec<(String, Format)>,
    #[serde(flatten)]
    figures: serde_json::Value,
}

pub fn run(args: &RenderArgs, platform: Platform) -> Result<()> {
    if args.method == Method::Sppm {
        return run_sppm(args, platform);
    }
    args.method()?;
    let outputs = args.outputs()?;
    let loaded = args.scene.load()?;
    let scene = &loaded.scene;
    warn_far_from_origin(scene, args.quiet);
    let options = args.options(scene)?;
    let cameras = match &args.camera_path {
        Some(p) => photonmap::scene::camera_path::load_camera_path(p, &scene.camera, scene.origin)?,
        None => vec![scene.camera.clone()],
    };
    let gpu = super::gpu(platform)?;
    let method = match (args.method, args.final_gather.is_some()) {
        (Method::Igi, _) => "igi",
        (Method::Differentials, _) => "differentials",
        (Method::Radiosity, _) => "radiosity",
        (_, true) => "final-gather",
        _ => "paper",
    };
    let provenance = provenance(loaded.provenance, &gpu, method, &options);
    let work = Work::Paper {
        passes: PassPlan::new(scene, &options).passes_per_sample(),
        samples: options.spp,
        views: cameras.len(),
        direct_only: args.direct_only,
    };
    let mut observer = CliObserver::new(args, scene, &outputs, work);
    let out = render::render_views(&gpu, scene, &options, &cameras, &mut observer)?;
    observer.finish()?;
    let written = write_images(&out.image, outputs.images(), &provenance)?;
    if let Some(path) = &args.reference_software {
        let leak = options.method.estimate().map(|e| e.leak);
        if !args.quiet && leak.is_some_and(|l| l != LeakTest::None) {
            eprintln!("note: the software reference is the paper's estimate, with no leak test; add --leak-test none to compare like with like");
        }
        write_software_reference(&out, scene, path, args.quiet)?;
    }
    if args.json {
        let photon_map = options.method.photon_map();
        let igi = match &options.method {
            render::Method::Igi(o) => Some(&o.method),
            _ => None,
        };
        super::print_json(&Report {
            provenance: &provenance,
            outputs: written.clone(),
            figures: serde_json::json!({
                "method": method,
                "timings": out.timings,
                "estimates": out.estimates(),
                "final_gather": photon_map.and_then(|o| o.final_gather.clone()),
                "gathers": out.gathers(),
                "adaptive": photon_map.and_then(|o| o.adaptive.clone()),
                "adaptive_samples": out.adaptive(),
                "igi": igi,
                "vpls": out.vpls(),
                "igi_samples": out.igi(),
                "differentials": out.differentials(),
                "footprint_samples": out.footprint_estimates(),
                "radiosity": out.radiosity(),
            }),
        })?;
    }
    if args.explain {
        print_explain(&out.explain(scene, &options));
    }
    if !args.quiet {
        print_summary(&out, &options, &written);
    }
    Ok(())
}

fn provenance(
    p: Provenance,
    gpu: &photonmap::gpu::Gpu,
    method: &str,
    o: &RenderOptions,
) -> Provenance {
    let mut p = super::with_driver(p, gpu);
    p.method = method.into();
    (p.seed, p.spp, p.width, p.height) = (o.seed, o.spp, o.width, o.height);
    p
}

fn print_explain(lines: &[photonmap::render::ExplainLine]) {
    for l in lines {
        let what = if l.ran { "run " } else { "skip" };
        eprintln!("{what} {:<34} {:>6} passes  {}", l.stage, l.passes, l.why);
    }
}

/// `--method sppm`: one view, iterations until --iterations or --time.
fn run_sppm(args: &RenderArgs, platform: Platform) -> Result<()> {
    args.method()?;
    let outputs = args.outputs()?;
    let loaded = args.scene.load()?;
    let scene = &loaded.scene;
    warn_far_from_origin(scene, args.quiet);
    let options = args.options(scene)?;
    let gpu = super::gpu(platform)?;
    let provenance = provenance(loaded.provenance, &gpu, "sppm", &options);
    if args.adaptive
        && args.sppm.iterations.is_none()
        && args.sppm.time.is_some()
        && args.sppm.adaptive_pilot.is_none()
    {
        bail!("--adaptive with --time alone cannot take its pilot as an eighth of the iterations: give --adaptive-pilot N (iterations at every pixel before the plan) or --iterations");
    }
    let work = Work::Iterations {
        iterations: args.sppm.iteration_limit(),
        seconds: args.sppm.time,
    };
    let mut observer = CliObserver::new(args, scene, &outputs, work);
    let render::Method::Sppm(WithPhotons { method: sppm, .. }) = &options.method else {
        unreachable!("--method sppm gives Method::Sppm");
    };
    let out = render::sppm::render_sppm(&gpu, scene, &options, sppm, &mut observer)?;
    observer.finish()?;
    let written = write_images(&out.image, outputs.images(), &provenance)?;
    if args.json {
        super::print_json(&Report {
            provenance: &provenance,
            outputs: written.clone(),
            figures: serde_json::json!({
                "method": "sppm",
                "sppm": sppm,
                "iterations": out.iterations,
                "stopped_by": out.stopped_by,
                "photons_emitted": out.photons_emitted,
                "initial_radius": out.initial_radius,
                "final_largest_radius": out.final_largest_radius,
                "adaptive_pilot": out.adaptive.as_ref().map(|a| a.0),
                "adaptive_samples": out.adaptive.as_ref().map(|a| &a.1),
                "timings": out.timings,
            }),
        })?;
    }
    if args.explain {
        print_explain(&out.explain);
    }
    if !args.quiet {
        eprint!("{}", out.timings.table());
        eprintln!(
            "SPPM: {} iterations in {:.1} s (stopped by {}), {} photons emitted, radius {} -> {:.5} (largest)",
            out.iterations,
            out.timings.wall_seconds,
            match out.stopped_by {
                StopReason::Iterations => "its iterations",
                StopReason::Time => "--time",
            },
            out.photons_emitted,
            out.initial_radius,
            out.final_largest_radius
        );
        if let Some((pilot, s)) = &out.adaptive {
            let pixels = (options.width * options.height) as u64;
            eprintln!(
                "adaptive sampling: after a pilot of {pilot} iterations, the photon half is interpolated at {} of {pixels} pixels and gathered at the other {} ({:.1}%)",
                s.interpolated,
                pixels - s.interpolated,
                100.0 * (pixels - s.interpolated) as f64 / pixels as f64
            );
        }
        for (p, _) in &written {
            eprintln!("wrote {p}");
        }
    }
    Ok(())
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

/// Writes the final image to every output, all or none; returns what was written.
fn write_images(
    image: &Image,
    outputs: &[(PathBuf, Format)],
    provenance: &Provenance,
) -> Result<Vec<(String, Format)>> {
    if image.has_non_finite() {
        bail!("the render produced NaN or infinite pixels: nothing was written (a bug; please report it with the scene)");
    }
    // Encode everything first, so a failure writes nothing.
    let encoded: Vec<(PathBuf, Vec<u8>)> = outputs
        .iter()
        .map(|(p, f)| Ok((p.clone(), f.encode(image, provenance)?)))
        .collect::<Result<_>>()?;
    let files: Vec<(&Path, &[u8])> = encoded
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    write_all_atomically(&files)?;
    Ok(outputs
        .iter()
        .map(|(p, f)| (p.display().to_string(), *f))
        .collect())
}

fn write_software_reference(
    out: &render::RenderOutput,
    scene: &Scene,
    path: &Path,
    quiet: bool,
) -> Result<()> {
    let wall = std::time::Instant::now();
    let img = render::software::software_image(out, scene)
        .ok_or_else(|| anyhow!("no photon map to estimate from"))?;
    write_atomically(path, &img.png_bytes()?)?;
    if !quiet {
        eprintln!(
            "software reference (kd-tree) in {:.2} s: wrote {}",
            wall.elapsed().as_secs_f64(),
            path.display()
        );
    }
    Ok(())
}

fn print_summary(
    out: &render::RenderOutput,
    options: &RenderOptions,
    written: &[(String, Format)],
) {
    eprint!("{}", out.timings.table());
    if !out.estimates().is_empty() {
        let passes: u32 = out.estimates().iter().map(|e| e.passes).sum();
        let draws: u64 = out.estimates().iter().map(|e| e.tile_draws).sum();
        let e = &out.estimates()[0];
        eprintln!(
            "radiance estimate: {passes} passes in {} run{}, {} of {} pixels searched, {draws} tile draws of {} tiles",
            out.estimates().len(),
            if out.estimates().len() == 1 { "" } else { "s" },
            e.query_pixels,
            options.width as u64 * options.height as u64,
            e.tiles
        );
    }
    if let Some(g) = out.gathers().first() {
        // Totals over every eye sample (and, adaptive, every level).
        let passes: u32 = out.gathers().iter().map(|g| g.estimate_passes).sum();
        let batches: u32 = out.gathers().iter().map(|g| g.batches).sum();
        let hits: u64 = out.gathers().iter().map(|g| g.queries).sum();
        eprintln!(
            "final gather: {} rays a pixel; {batches} batches, {hits} gather rays reached a diffuse surface, {passes} estimate passes in all",
            g.rays_per_pixel,
        );
    }
    if let (Some(v), Some(s)) = (out.vpls(), out.igi().first()) {
        eprintln!(
            "IGI: {} VPLs from {} light paths (bounding distance {}); {:.1} VPL shadow rays at each of {} shading points; caustics {}",
            v.vpls,
            v.paths,
            v.min_distance,
            s.vpls_per_point,
            s.shading_points,
            if out.photons().is_some() {
                "from the caustic photon map"
            } else {
                "none (nothing specular in the scene)"
            }
        );
    }
    if let Some(r) = out.radiosity() {
        eprintln!(
            "radiosity: {} patches in {} tiles of {} x {} ({} splits{}), {} elements; {} shots in {:.2} s, {}: {:.2}% of the power unshot; caustics {}",
            r.patches,
            r.tiles,
            r.element_resolution,
            r.element_resolution,
            r.splits,
            if r.atlas_full { ", the atlas full" } else { "" },
            r.elements,
            r.shots,
            r.seconds,
            if r.converged { "converged" } else { "stopped at --max-shots" },
            100.0 * r.unshot_fraction,
            if out.photons().is_some() {
                "from the caustic photon map"
            } else {
                "none (nothing specular in the scene)"
            }
        );
    }
    if let (Some(d), Some(s)) = (out.differentials(), out.footprint_estimates().first()) {
        let pilot = d.pilot_mean_diffuse_footprints.map_or(String::new(), |m| {
            format!(" (auto: {m:.4} diffuse footprints a hit at s = 1 in the pilot)")
        });
        eprintln!(
            "photon differentials: {} footprints ({} diffuse, {} caustic, {} degenerate); s = {:.2}{pilot}, caustics {}, r_max {}; BVH of {} leaves of {} (auto {}); {:.1} footprints hold a first hit on average (k_PD), {:.1} nodes and {:.1} footprints examined, {} passes",
            d.footprints,
            d.diffuse_footprints,
            d.footprints - d.diffuse_footprints,
            d.degenerate_footprints,
            d.smoothing,
            d.caustic_smoothing,
            d.max_radius,
            d.leaves,
            d.leaf_size,
            d.auto_leaf_size,
            s.mean_footprints,
            s.mean_nodes,
            s.mean_examined,
            s.passes,
        );
    }
    if !out.adaptive().is_empty() {
        let computed: u64 = out.adaptive().iter().map(|a| a.computed).sum();
        let all: u64 = out.adaptive().iter().map(|a| a.pixels_with_hits).sum();
        let levels: Vec<String> = out.adaptive()[0]
            .levels
            .iter()
            .map(|(s, c, i)| format!("stride {s}: {c} computed, {i} interpolated"))
            .collect();
        eprintln!(
            "adaptive sampling: global light computed at {computed} of {all} pixels with a diffuse hit ({:.1}%); {}",
            100.0 * computed as f64 / all.max(1) as f64,
            levels.join("; ")
        );
    }
    for (p, _) in written {
        eprintln!("wrote {p}");
    }
}

/// A snapshot written during the estimate.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SnapshotRecord {
    pub file: String,
    pub pass: u32,
    /// Seconds of radiance estimate so far (writing snapshots not counted).
    pub seconds: f64,
    pub searching_pixels: u64,
    /// A progressive render's last snapshot: what ended it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped_by: Option<StopReason>,
}

/// Writes the running estimate of a render's first estimate as numbered PNGs
/// into a folder, the final image last, with snapshots.json listing them.
pub struct SnapshotWriter {
    dir: PathBuf,
    every: SnapshotEvery,
    pub written: Vec<SnapshotRecord>,
    last: (u32, f64),
}

impl SnapshotWriter {
    pub fn new(dir: PathBuf, every: SnapshotEvery) -> Self {
        Self {
            dir,
            every,
            written: Vec::new(),
            last: (0, 0.0),
        }
    }
}

impl RenderObserver for SnapshotWriter {
    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> photonmap::Result<()> {
        // Snapshots follow the first estimate only.
        if pass.at.view != 0 || pass.at.sample != 0 {
            return Ok(());
        }
        let due = pass.finished
            || pass.pass == 0
            || match self.every {
                SnapshotEvery::Passes(n) => pass.pass >= self.last.0 + n,
                SnapshotEvery::Seconds(s) => pass.seconds >= self.last.1 + s,
            };
        if !due {
            return Ok(());
        }
        let file = format!("snapshot_{:04}.png", self.written.len());
        write_atomically(&self.dir.join(&file), &pass.image()?.png_bytes()?)?;
        self.written.push(SnapshotRecord {
            file,
            pass: pass.pass,
            seconds: pass.seconds,
            searching_pixels: pass.searching,
            stopped_by: pass.stopped_by,
        });
        self.last = (pass.pass, pass.seconds);
        if pass.finished {
            let index = serde_json::to_string_pretty(&self.written).unwrap_or_default();
            write_atomically(&self.dir.join("snapshots.json"), index.as_bytes())?;
        }
        Ok(())
    }
}

/// The CLI's observer: the progress report, snapshots of the first estimate,
/// and the frames of a fly-through.
struct CliObserver {
    progress: ProgressReport,
    snapshots: Option<SnapshotWriter>,
    frames: Option<PathBuf>,
    frame_times: Vec<f64>,
    clock: std::time::Instant,
}

impl CliObserver {
    fn new(args: &RenderArgs, scene: &Scene, outputs: &Outputs, work: Work) -> Self {
        Self {
            progress: ProgressReport::new(args.quiet, &scene.name, work),
            snapshots: args
                .snapshots
                .clone()
                .map(|d| SnapshotWriter::new(d, args.every)),
            frames: match outputs {
                Outputs::Frames(dir, _) => Some(dir.clone()),
                Outputs::Images(_) => None,
            },
            frame_times: Vec::new(),
            clock: std::time::Instant::now(),
        }
    }

    /// Writes the index of a fly-through's frames.
    fn finish(&mut self) -> Result<()> {
        self.progress.finish();
        if let Some(dir) = &self.frames {
            let index = serde_json::json!({ "frames": self.frame_times.len(), "seconds_since_start": self.frame_times });
            write_atomically(&dir.join("frames.json"), index.to_string().as_bytes())?;
        }
        Ok(())
    }
}

impl RenderObserver for CliObserver {
    fn progress(&mut self, p: &Progress<'_>) {
        self.progress.update(p);
    }

    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> photonmap::Result<()> {
        match &mut self.snapshots {
            Some(s) => s.estimate_pass(pass),
            None => Ok(()),
        }
    }

    fn frame(&mut self, view: usize, image: &Image) -> photonmap::Result<()> {
        if let Some(dir) = &self.frames {
            write_atomically(
                &dir.join(format!("frame_{view:04}.png")),
                &image.png_bytes()?,
            )?;
            self.frame_times.push(self.clock.elapsed().as_secs_f64());
        }
        Ok(())
    }
}
