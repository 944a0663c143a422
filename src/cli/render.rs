//! `photonmap render`: one image, or a fly-through of frames on one photon map.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};
use clap::Args;

use photonmap::gpu::Platform;
use photonmap::image::write_atomically;
use photonmap::render::{
    self, EstimatePass, GlobalIllumination, Image, Progress, RenderObserver, RenderOptions,
};
use photonmap::scene::{embedded, Scene};

use super::args::{in_range, EstimateArgs, Method, PhotonMapArgs, SppmArgs};

/// Render a scene to a PNG (sRGB) and optionally an EXR (linear float RGB).
#[derive(Args)]
pub struct RenderArgs {
    /// Scene file (TOML; see README.md), or the name of an embedded scene
    /// (`photonmap scenes` lists them: glass_ball, ring, cornell_box, ...).
    pub scene: PathBuf,
    /// Output PNG path (with --camera-path: the frames go to --out instead).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Also write linear float RGB to this OpenEXR path.
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
    /// No progress bar and no timing table on stderr.
    #[arg(long)]
    pub quiet: bool,
    /// Print the per-stage timings as JSON on stdout.
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
    #[command(flatten)]
    pub sppm: SppmArgs,
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

/// Where the images go.
enum Outputs {
    Image { png: PathBuf, exr: Option<PathBuf> },
    Frames { dir: PathBuf, exr: Option<PathBuf> },
}

impl RenderArgs {
    /// Checks every output path before any work.
    fn outputs(&self) -> Result<Outputs> {
        if let Some(p) = &self.reference_software {
            super::check_output(p, "png", "--reference-software")?;
        }
        if let Some(e) = &self.exr {
            super::check_output(e, "exr", "--exr")?;
        }
        if let Some(dir) = &self.snapshots {
            if !dir.is_dir() {
                bail!("--snapshots {}: the folder does not exist", dir.display());
            }
        }
        match (&self.output, &self.out) {
            (Some(png), None) => {
                super::check_output(png, "png", "-o")?;
                Ok(Outputs::Image {
                    png: png.clone(),
                    exr: self.exr.clone(),
                })
            }
            (None, Some(dir)) => {
                if !dir.is_dir() {
                    bail!("--out {}: the folder does not exist", dir.display());
                }
                Ok(Outputs::Frames {
                    dir: dir.clone(),
                    exr: self.exr.clone(),
                })
            }
            _ => bail!("-o OUTPUT.png is required (or --camera-path PATH.toml --out DIR)"),
        }
    }

    fn options(&self, scene: &Scene) -> RenderOptions {
        let mut options = RenderOptions::for_scene(scene);
        options.seed = self.seed;
        options.spp = self.spp;
        options.width = self.width.unwrap_or(options.width);
        options.height = self.height.unwrap_or(options.height);
        options.global = (!self.direct_only).then(|| GlobalIllumination {
            photons: (&self.photons).into(),
            estimate: (&self.estimate).into(),
        });
        options
    }
}

pub fn run(args: &RenderArgs, platform: Platform) -> Result<()> {
    if args.method == Method::Sppm {
        return run_sppm(args, platform);
    }
    let outputs = args.outputs()?;
    let scene = embedded::load_path_or_name(&args.scene)?;
    warn_far_from_origin(&scene, args.quiet);
    let options = args.options(&scene);
    let cameras = match &args.camera_path {
        Some(p) => photonmap::scene::camera_path::load_camera_path(p, &scene.camera)?,
        None => vec![scene.camera.clone()],
    };
    let gpu = super::gpu(platform)?;
    let mut observer = CliObserver::new(args, &scene, &options, &outputs);
    let out = render::render_views(&gpu, &scene, &options, &cameras, &mut observer)?;
    observer.finish()?;
    if out.image.has_non_finite() {
        bail!("the render produced NaN or infinite pixels: nothing was written (a bug; please report it with the scene)");
    }
    let written = write_image(&out.image, &outputs)?;
    if args.json {
        super::print_json(&out.timings)?;
    }
    if let Some(path) = &args.reference_software {
        write_software_reference(&out, &scene, path, args.quiet)?;
    }
    if args.explain {
        for l in out.explain(&scene, &options) {
            let what = if l.ran { "run " } else { "skip" };
            eprintln!("{what} {:<34} {:>6} passes  {}", l.stage, l.passes, l.why);
        }
    }
    if !args.quiet {
        print_summary(&out, &options, &written);
    }
    Ok(())
}

/// `--method sppm`: one view, iterations until --iterations or --time.
fn run_sppm(args: &RenderArgs, platform: Platform) -> Result<()> {
    if args.camera_path.is_some()
        || args.direct_only
        || args.reference_software.is_some()
        || args.spp > 1
    {
        bail!("--method sppm renders one view with its own eye samples and photons: drop --camera-path, --direct-only, --reference-software and --spp");
    }
    let outputs = args.outputs()?;
    let scene = embedded::load_path_or_name(&args.scene)?;
    warn_far_from_origin(&scene, args.quiet);
    let options = args.options(&scene);
    let gpu = super::gpu(platform)?;
    let mut observer = CliObserver::new(args, &scene, &options, &outputs);
    let out =
        render::sppm::render_sppm(&gpu, &scene, &options, &(&args.sppm).into(), &mut observer)?;
    observer.finish()?;
    if out.image.has_non_finite() {
        bail!("the render produced NaN or infinite pixels: nothing was written (a bug; please report it with the scene)");
    }
    let written = write_image(&out.image, &outputs)?;
    if args.json {
        super::print_json(&serde_json::json!({
            "method": "sppm",
            "iterations": out.iterations,
            "photons_emitted": out.photons_emitted,
            "initial_radius": out.initial_radius,
            "final_largest_radius": out.final_largest_radius,
            "timings": out.timings,
        }))?;
    }
    if args.explain {
        for l in &out.explain {
            let what = if l.ran { "run " } else { "skip" };
            eprintln!("{what} {:<34} {:>6} passes  {}", l.stage, l.passes, l.why);
        }
    }
    if !args.quiet {
        eprint!("{}", out.timings.table());
        eprintln!(
            "SPPM: {} iterations, {} photons emitted, radius {} -> {:.5} (largest)",
            out.iterations, out.photons_emitted, out.initial_radius, out.final_largest_radius
        );
        for p in &written {
            eprintln!("wrote {}", p.display());
        }
    }
    Ok(())
}

fn warn_far_from_origin(scene: &Scene, quiet: bool) {
    let ratio = scene.offset_ratio();
    if ratio > 1000.0 && !quiet {
        eprintln!(
            "warning: coordinates reach {ratio:.0} x the scene's size; 32-bit floats resolve them only to ~{:.0e} of it, so fine detail (sharp caustics) may blur: move the scene near the origin",
            ratio * f32::EPSILON
        );
    }
}

/// Writes the final image (the frames are already written); returns what was written.
fn write_image(image: &Image, outputs: &Outputs) -> Result<Vec<PathBuf>> {
    // Encode everything first, so a failure writes nothing.
    let (png, exr) = match outputs {
        Outputs::Image { png, exr } => (Some(png), exr.as_ref()),
        Outputs::Frames { exr, .. } => (None, exr.as_ref()),
    };
    let png_bytes = png.map(|_| image.png_bytes()).transpose()?;
    let exr_bytes = exr.map(|_| image.exr_bytes()).transpose()?;
    let mut written = Vec::new();
    for (path, bytes) in [(png, png_bytes), (exr, exr_bytes)] {
        if let (Some(path), Some(bytes)) = (path, bytes) {
            write_atomically(path, &bytes)?;
            written.push(path.clone());
        }
    }
    Ok(written)
}

fn write_software_reference(
    out: &render::RenderOutput,
    scene: &Scene,
    path: &Path,
    quiet: bool,
) -> Result<()> {
    let wall = std::time::Instant::now();
    let img = render::software::software_image(&out.state, scene)
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

fn print_summary(out: &render::RenderOutput, options: &RenderOptions, written: &[PathBuf]) {
    eprint!("{}", out.timings.table());
    if let Some(e) = &out.estimate {
        eprintln!(
            "radiance estimate: {} passes, {} of {} pixels searched, {} tile draws of {} tiles",
            e.passes,
            e.query_pixels,
            options.width as u64 * options.height as u64,
            e.tile_draws,
            e.tiles
        );
    }
    for p in written {
        eprintln!("wrote {}", p.display());
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
        });
        self.last = (pass.pass, pass.seconds);
        if pass.finished {
            let index = serde_json::to_string_pretty(&self.written).unwrap_or_default();
            write_atomically(&self.dir.join("snapshots.json"), index.as_bytes())?;
        }
        Ok(())
    }
}

/// The CLI's observer: the progress bar, snapshots of the first estimate, and
/// the frames of a fly-through.
struct CliObserver {
    bar: indicatif::ProgressBar,
    scene: String,
    snapshots: Option<SnapshotWriter>,
    frames: Option<PathBuf>,
    frame_times: Vec<f64>,
    clock: std::time::Instant,
}

impl CliObserver {
    fn new(args: &RenderArgs, scene: &Scene, options: &RenderOptions, outputs: &Outputs) -> Self {
        let bar = if args.quiet {
            indicatif::ProgressBar::hidden()
        } else {
            let b = indicatif::ProgressBar::new(1);
            b.set_style(
                indicatif::ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} {elapsed}")
                    .expect("valid template")
                    .progress_chars("=> "),
            );
            b.set_message(format!(
                "{} {}x{}",
                scene.name, options.width, options.height
            ));
            b
        };
        Self {
            bar,
            scene: scene.name.clone(),
            snapshots: args
                .snapshots
                .clone()
                .map(|d| SnapshotWriter::new(d, args.every)),
            frames: match outputs {
                Outputs::Frames { dir, .. } => Some(dir.clone()),
                Outputs::Image { .. } => None,
            },
            frame_times: Vec::new(),
            clock: std::time::Instant::now(),
        }
    }

    /// Writes the index of a fly-through's frames.
    fn finish(&mut self) -> Result<()> {
        self.bar.finish_and_clear();
        if let Some(dir) = &self.frames {
            let index = serde_json::json!({ "frames": self.frame_times.len(), "seconds_since_start": self.frame_times });
            write_atomically(&dir.join("frames.json"), index.to_string().as_bytes())?;
        }
        Ok(())
    }
}

impl RenderObserver for CliObserver {
    fn progress(&mut self, p: &Progress<'_>) {
        self.bar.set_message(format!("{} {}", self.scene, p.stage));
        self.bar.set_length(p.total.max(1));
        self.bar.set_position(p.done);
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
