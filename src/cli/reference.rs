//! `photonmap reference`: a reference image by stochastic progressive photon
//! mapping, which converges to the exact image, so that accuracy is measured
//! against truth and not against the paper's estimator itself. Two independent
//! halves (their own seeds) are rendered; their mean is the reference, half
//! their RMSE difference its remaining noise, and the change since a quarter of
//! the iterations bounds its remaining bias.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use serde::{Deserialize, Serialize};

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_atomically;
use photonmap::metrics::rmse;
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::sppm::{Sppm, SppmOptions};
use photonmap::render::{GlobalIllumination, Image, RenderOptions};
use photonmap::scene::Scene;
use photonmap::timing::Timings;

use super::args::in_range;

/// Render a reference of a scene by SPPM (it converges to the exact image):
/// two independent halves averaged, as EXR, with a JSON of its command, its
/// remaining noise and a bound on its remaining bias.
#[derive(Args)]
pub struct ReferenceArgs {
    #[command(flatten)]
    pub scene: super::args::SceneArgs,
    /// Output EXR (default: photonmap-out/reference/<scene>.sppm.exr under the
    /// current folder; a .json goes beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Render at 1/scale of the scene's resolution (1..=16).
    #[arg(long, default_value_t = 2, value_parser = in_range(1, 16))]
    pub scale: u32,
    /// SPPM iterations of each half (4..=1000000).
    #[arg(long, default_value_t = 1024, value_parser = in_range(4, 1_000_000))]
    pub iterations: u32,
    /// Photons emitted per iteration (64..=4194304).
    #[arg(long, default_value_t = 16384, value_parser = in_range(64, 1 << 22))]
    pub photons_per_iteration: u32,
    /// Every pixel's first radius (default: the scene's max_radius).
    #[arg(long)]
    pub radius: Option<f32>,
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Serialize, Deserialize, Debug, Clone)]
pub struct ReferenceInfo {
    pub scene: String,
    pub method: String,
    pub width: u32,
    pub height: u32,
    /// Iterations of each of the two halves.
    pub iterations: u32,
    pub photons_per_iteration: u32,
    pub initial_radius: f32,
    pub alpha: f32,
    /// RMSE of the reference's remaining noise: half the RMSE between the halves.
    pub residual_noise_rmse: f64,
    /// A bound on its remaining bias: SPPM's bias falls as i^-(1 - alpha), so
    /// the change from i/4 to i iterations is (4^(1 - alpha) - 1) times the
    /// bias left at i (noise removed).
    pub residual_bias_rmse: f64,
    pub seconds: f64,
    pub command: String,
    pub renderer: String,
}

pub fn run(a: &ReferenceArgs, platform: Platform) -> Result<()> {
    let scene = a.scene.load()?.scene;
    let out = a.out.clone().unwrap_or_else(|| {
        super::out_dir("reference").join(format!("{}.sppm.exr", stem(&a.scene.scene)))
    });
    if let Some(dir) = out
        .parent()
        .filter(|d| !d.as_os_str().is_empty() && a.out.is_none())
    {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    }
    super::check_output(&out, "exr", "--out")?;
    let gpu = super::gpu(platform)?;
    let mut command = format!(
        "photonmap reference {} --scale {} --iterations {} --photons-per-iteration {}",
        a.scene.scene.display(),
        a.scale,
        a.iterations,
        a.photons_per_iteration
    );
    if let Some(r) = a.radius {
        command += &format!(" --radius {r}");
    }
    for (k, v) in &a.scene.set {
        command += &format!(" --set {k}={v}");
    }
    let progress = super::progress_lines(a.quiet);
    let (img, info) = make_reference(&gpu, &scene, a, command, &progress)?;
    write_reference(&img, &info, &out)?;
    eprintln!(
        "wrote {} (remaining noise RMSE {:.5}, bias RMSE at most about {:.5})",
        out.display(),
        info.residual_noise_rmse,
        info.residual_bias_rmse
    );
    Ok(())
}

fn stem(scene: &Path) -> String {
    scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// The options every reference half runs with: the visibility leak test, so
/// that thin walls do not leak while the radius is still large.
pub fn reference_options(scene: &Scene, scale: u32, seed: u32) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    o.width = (scene.camera.width / scale).max(1);
    o.height = (scene.camera.height / scale).max(1);
    o.seed = seed;
    let mut gi = GlobalIllumination::default();
    gi.estimate.leak = LeakTest::Visibility;
    o.global = Some(gi);
    o
}

pub fn make_reference(
    gpu: &Gpu,
    scene: &Scene,
    a: &ReferenceArgs,
    command: String,
    progress: &dyn Fn(&str),
) -> Result<(Image, ReferenceInfo)> {
    let sppm = SppmOptions {
        iterations: a.iterations,
        photons_per_iteration: a.photons_per_iteration,
        initial_radius: a.radius,
        ..SppmOptions::default()
    };
    let wall = std::time::Instant::now();
    let mut halves = Vec::new();
    let mut quarters = Vec::new();
    let mut initial_radius = 0.0;
    for half in 0..2u32 {
        let options = reference_options(scene, a.scale, 1001 + half);
        let mut run = Sppm::new(gpu, scene, &options, &sppm)?;
        initial_radius = run.initial_radius;
        let mut timings = Timings::default();
        while run.iteration < a.iterations {
            run.iterate(&mut timings, &mut ())?;
            if run.iteration == a.iterations / 4 {
                quarters.push(run.image()?);
            }
            if run.iteration.is_multiple_of(64) {
                progress(&format!(
                    "reference {}: half {} of 2, iteration {} of {}",
                    scene.name,
                    half + 1,
                    run.iteration,
                    a.iterations
                ));
            }
        }
        halves.push(run.image()?);
    }
    let noise = rmse(&halves[0], &halves[1])? / 2.0;
    let quarter_noise = rmse(&quarters[0], &quarters[1])? / 2.0;
    let (full, quarter) = (Image::average(&halves), Image::average(&quarters));
    let change = rmse(&quarter, &full)?;
    let change2 = (change * change - noise * noise - quarter_noise * quarter_noise).max(0.0);
    let factor = 4f64.powf(1.0 - sppm.alpha as f64) - 1.0;
    let info = ReferenceInfo {
        scene: scene.name.clone(),
        method: "sppm".into(),
        width: full.width,
        height: full.height,
        iterations: a.iterations,
        photons_per_iteration: a.photons_per_iteration,
        initial_radius,
        alpha: sppm.alpha,
        residual_noise_rmse: noise,
        residual_bias_rmse: change2.sqrt() / factor,
        seconds: wall.elapsed().as_secs_f64(),
        command,
        renderer: gpu.capabilities().gl_renderer,
    };
    Ok((full, info))
}

pub fn write_reference(img: &Image, info: &ReferenceInfo, exr: &Path) -> Result<()> {
    write_atomically(exr, &img.exr_bytes()?)?;
    write_atomically(
        &exr.with_extension("json"),
        (serde_json::to_string_pretty(info)? + "\n").as_bytes(),
    )?;
    Ok(())
}

/// A reference and its JSON, as `photonmap reference` writes them.
pub fn read_reference(exr: &Path) -> Result<(Image, ReferenceInfo)> {
    let img = Image::read_exr(exr)?;
    let json = exr.with_extension("json");
    let info: ReferenceInfo = serde_json::from_str(
        &std::fs::read_to_string(&json).with_context(|| format!("reading {}", json.display()))?,
    )
    .with_context(|| format!("{}: not a reference's JSON", json.display()))?;
    Ok((img, info))
}
