//! `photonmap bench accuracy`: run time against error around a scene's
//! defaults, measured against a reference that does not share its estimator
//! (an SPPM reference, or independent ground truth: truth, not the paper's
//! estimator agreeing with itself). Each configuration renders several seeds,
//! so its error splits into bias (what more seeds would not remove) and noise
//! (what they would); SPPM and the other methods sit on the same front.
//! `--regions` splits each run's energy and error by the surfaces the pixels
//! see first and by named rectangles.

mod plot;
mod regions;
mod report;
mod sweep;

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_atomically;
use photonmap::metrics::compare;
use photonmap::render::sppm::{render_sppm, SppmOptions};
use photonmap::render::{
    render, AdaptiveOptions, EstimateMode, FinalGatherOptions, Image, Method, WithCausticMap,
    WithPhotons,
};
use photonmap::scene::{embedded, Scene};

use super::output::{command_line, folder, stem, write_json, BenchOutput};
use super::reference::{read_reference, reference_options, ReferenceInfo};
use super::scene::{default_reference, reference_scale, SEED};
use plot::{bias_map, csv, png_plot, svg_plot};
use regions::{RegionArgs, Regions};
use report::{AccuracyReport, AccuracyRun, RunMethod};

/// `bench accuracy`'s options.
#[derive(Args)]
pub struct AccuracyArgs {
    /// Scene file, or the name of an embedded scene.
    #[arg(long)]
    pub scene: PathBuf,
    /// The reference: an SPPM reference (`photonmap reference`, with its
    /// JSON beside it), or any EXR of the scene's size divided by a whole
    /// number, such as independent ground truth (its own noise is then not
    /// known, and the bias split counts it as bias). Default:
    /// photonmap-out/reference/<scene>.sppm.exr, then
    /// reference_images/<scene>.sppm.exr, under the current folder.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Compare only the pixels where this PNG (the reference's size) is
    /// white, such as the ground truth's interior mask.
    #[arg(long, value_name = "PNG")]
    pub mask: Option<PathBuf>,
    /// Output folder (default: photonmap-out/accuracy/<scene>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A small sweep with two seeds a configuration.
    #[arg(long)]
    pub quick: bool,
    /// Seeds per configuration (2..=64; default 4, or 2 with --quick).
    #[arg(long, value_parser = crate::cli::args::in_range(2, 64))]
    pub seeds: Option<u32>,
    /// Only the runs whose label contains this text (e.g. "scene defaults",
    /// "SPPM", "max radius"), or, after a leading "=", is exactly it ("=IGI":
    /// IGI at its defaults alone); repeat it for the runs matching any.
    #[arg(long, value_name = "TEXT")]
    pub only: Vec<String>,
    #[command(flatten)]
    pub regions: RegionArgs,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// What `bench_accuracy` runs and against what.
pub struct Sweep<'a> {
    pub reference: &'a Path,
    pub mask: Option<&'a Path>,
    pub quick: bool,
    pub seeds: u32,
    pub only: &'a [String],
    pub regions: &'a RegionArgs,
}

pub fn run_bench(a: &AccuracyArgs, platform: Platform) -> Result<()> {
    let scene = embedded::load_path_or_name(&a.scene)?;
    let reference = match &a.reference {
        Some(r) => r.clone(),
        None => default_reference(&a.scene),
    };
    if !reference.is_file() {
        bail!(
            "no SPPM reference at {}: make one with `photonmap reference {}` (or give --reference)",
            reference.display(),
            a.scene.display()
        );
    }
    if let Some(m) = a.mask.as_ref().filter(|m| !m.is_file()) {
        bail!("--mask {}: no such file", m.display());
    }
    a.regions.check()?;
    let gpu = crate::cli::gpu(platform)?;
    let sweep = Sweep {
        reference: &reference,
        mask: a.mask.as_deref(),
        quick: a.quick,
        seeds: a.seeds.unwrap_or(if a.quick { 2 } else { 4 }),
        only: &a.only,
        regions: &a.regions,
    };
    let report = bench_accuracy(&gpu, &scene, &sweep, &a.output.progress())?;
    let dir = folder(a.out.as_deref(), "accuracy", Some(&stem(&a.scene)))?;
    let write = |name: &str, bytes: &[u8]| write_atomically(&dir.join(name), bytes);
    write("accuracy.csv", csv(&report).as_bytes())?;
    write_json(&dir.join("accuracy.json"), &report)?;
    write("accuracy.svg", svg_plot(&report).as_bytes())?;
    write("accuracy.png", &png_plot(&report))?;
    if let Some(map) = &report.bias_map {
        write("bias.png", &map.png_bytes()?)?;
    }
    if !report.regions.is_empty() {
        write("regions.csv", regions::csv(&report).as_bytes())?;
        write("regions.md", regions::markdown(&report).as_bytes())?;
        std::fs::create_dir_all(dir.join("bias"))?;
        for (label, map) in &report.bias_maps {
            write(
                &format!("bias/{}.png", regions::slug(label)),
                &map.png_bytes()?,
            )?;
        }
    }
    a.output.print(&report, print_table)?;
    eprintln!("wrote {}", dir.display());
    Ok(())
}

fn print_table(report: &AccuracyReport) {
    println!(
        "{:<26} {:>8} {:>9} {:>9} {:>9} {:>7} {:>5}",
        "run", "seconds", "RMSE", "bias", "noise", "SSIM", "front"
    );
    for r in &report.runs {
        println!(
            "{:<26} {:>8.3} {:>9.5} {:>9.5} {:>9.5} {:>7.4} {:>5}",
            r.label,
            r.seconds,
            r.rmse,
            r.bias_rmse,
            r.noise_rmse,
            r.ssim,
            if r.on_pareto_front { "*" } else { "" }
        );
    }
    println!("recommended: {}", report.recommended);
    regions::print_table(report);
}

/// One render of a configuration with `seed`: its image and wall seconds.
fn render_config(
    gpu: &Gpu,
    scene: &Scene,
    c: &AccuracyRun,
    scale: u32,
    seed: u32,
) -> Result<(Image, f64)> {
    let mut s = scene.clone();
    s.photon_map.photons_stored = c.photons_stored;
    s.photon_map.k = c.k;
    s.photon_map.max_radius = c.max_radius;
    s.render.shadow_rays = c.shadow_rays;
    let mut o = reference_options(&s, scale, seed);
    o.spp = c.spp;
    let gi = o.photon_map_mut().expect("global illumination");
    gi.photons.build = c.build;
    gi.photons.grid = c.grid;
    gi.estimate.leak = c.leak;
    gi.estimate.mode = if c.tile == 0 {
        EstimateMode::FullScreen
    } else {
        EstimateMode::Tiled { tile: c.tile }
    };
    if let RunMethod::FinalGather { gather_rays } = c.method {
        gi.final_gather = Some(FinalGatherOptions {
            rays: gather_rays,
            ..FinalGatherOptions::default()
        });
    }
    gi.adaptive = c.adaptive.then(AdaptiveOptions::default);
    let map = gi.clone();
    o.method = match &c.method {
        RunMethod::Igi(i) => Method::Igi(WithCausticMap::from_map(map, i.clone())),
        RunMethod::Differentials(d) => Method::Differentials(WithPhotons::from_map(map, d.clone())),
        RunMethod::Radiosity(r) => Method::Radiosity(WithCausticMap::from_map(map, r.clone())),
        _ => Method::PhotonMap(map),
    };
    let wall = std::time::Instant::now();
    let image = if let RunMethod::Sppm { sppm_iterations } = c.method {
        let sppm = SppmOptions {
            iterations: sppm_iterations,
            adaptive: c.adaptive.then(AdaptiveOptions::default),
            ..SppmOptions::default()
        };
        render_sppm(gpu, &s, &o, &sppm, &mut ())?.image
    } else {
        render(gpu, &s, &o, &mut ())?.image
    };
    Ok((image, wall.elapsed().as_secs_f64()))
}

/// The reference's image, and its JSON when it has one (an SPPM reference).
fn read_any_reference(path: &Path) -> Result<(Image, Option<ReferenceInfo>)> {
    if path.with_extension("json").is_file() {
        let (image, info) = read_reference(path)?;
        return Ok((image, Some(info)));
    }
    Ok((Image::read_exr(path)?, None))
}

pub fn bench_accuracy(
    gpu: &Gpu,
    scene: &Scene,
    sweep: &Sweep<'_>,
    progress: &dyn Fn(&str),
) -> Result<AccuracyReport> {
    let (reference_img, info) = read_any_reference(sweep.reference)?;
    let scale = reference_scale(sweep.reference, &reference_img, scene)?;
    let mask = match sweep.mask {
        Some(m) => Some(crate::cli::compare::read_mask(m, &reference_img)?),
        None => None,
    };
    let mut configs = sweep::sweep(scene, sweep.quick);
    if !sweep.only.is_empty() {
        let only = sweep.only;
        let labels: Vec<String> = configs.iter().map(|c| c.run.label.clone()).collect();
        let matches = |label: &str, text: &str| match text.strip_prefix('=') {
            Some(exact) => label == exact,
            None => label.contains(text),
        };
        configs.retain(|c| only.iter().any(|text| matches(&c.run.label, text)));
        if configs.is_empty() {
            bail!(
                "--only {only:?} matches no run; the runs are: {}",
                labels.join(", ")
            );
        }
    }
    let regions = if sweep.regions.wanted() {
        progress("regions (first hits)");
        Regions::new(gpu, scene, &reference_img, mask.as_deref(), sweep.regions)?
    } else {
        Regions::default()
    };
    let reference_noise = info.as_ref().map_or(0.0, |i| i.residual_noise_rmse);
    let mut runs = Vec::new();
    let (mut bias, mut bias_maps) = (None, Vec::new());
    for (i, c) in configs.iter().enumerate() {
        progress(&format!("{} ({}/{})", c.run.label, i + 1, configs.len()));
        let mut images = Vec::new();
        let mut seconds = 0.0;
        for seed in 0..sweep.seeds {
            let (img, s) = render_config(gpu, scene, &c.run, scale, SEED + seed)?;
            images.push(img);
            seconds += s;
        }
        let mean = Image::average(&images);
        let split = bias_and_noise(
            &images,
            &mean,
            &reference_img,
            mask.as_deref(),
            reference_noise,
        )?;
        let one: Vec<_> = images
            .iter()
            .map(|img| compare(img, &reference_img, mask.as_deref()))
            .collect::<Result<_, _>>()?;
        let n = images.len() as f64;
        let mut run = c.run.clone();
        let average =
            |f: fn(&photonmap::metrics::Metrics) -> f64| one.iter().map(f).sum::<f64>() / n;
        run.seconds = seconds / n;
        run.rmse = average(|m| m.rmse);
        run.rel_mse = average(|m| m.rel_mse);
        run.ssim = average(|m| m.ssim);
        run.rel_rmse = average(|m| m.rel_rmse);
        run.energy = compare(&mean, &reference_img, mask.as_deref())?.energy;
        (run.bias_rmse, run.noise_rmse) = split;
        run.regions = regions.score(&images, &mean, &reference_img)?;
        let map = || bias_map(&mean, &reference_img);
        if run.label == "scene defaults" {
            bias = Some(map());
        }
        if !regions.is_empty() {
            bias_maps.push((run.label.clone(), map().0));
        }
        runs.push(run);
    }
    mark_front(&mut runs);
    let best = runs.iter().map(|r| r.rmse).fold(f64::INFINITY, f64::min);
    let recommended = runs
        .iter()
        .filter(|r| r.on_pareto_front && r.rmse <= best * 1.1)
        .min_by(|a, b| a.seconds.total_cmp(&b.seconds))
        .map(|r| r.label.clone())
        .unwrap_or_default();
    Ok(AccuracyReport {
        command: command_line(),
        scene: scene.name.clone(),
        reference_file: sweep.reference.display().to_string(),
        reference: info,
        mask: sweep.mask.map(|m| m.display().to_string()),
        pixels_compared: mask.as_ref().map_or(reference_img.pixels.len(), |m| {
            m.iter().filter(|&&p| p).count()
        }),
        regions: regions.sizes(),
        renderer: gpu.capabilities().gl_renderer,
        seeds: sweep.seeds,
        runs,
        recommended,
        bias_map_scale: bias.as_ref().map(|b| b.1),
        bias_map: bias.map(|b| b.0),
        bias_maps,
    })
}

/// Bias and noise of one render, as RMS over the compared pixels: noise from
/// the per-pixel spread of the seeds, bias from the seeds' mean against the
/// reference with the mean's own noise and the reference's removed.
fn bias_and_noise(
    images: &[Image],
    mean: &Image,
    reference: &Image,
    mask: Option<&[bool]>,
    reference_noise: f64,
) -> Result<(f64, f64)> {
    let n = images.len() as f64;
    // The per-pixel sample variance (photonmap::regress), averaged over channels.
    let var = photonmap::regress::variance(images, mean);
    let kept = |i: usize| mask.is_none_or(|m| m[i]);
    let (sum, count) = var
        .pixels
        .iter()
        .enumerate()
        .filter(|(i, _)| kept(*i))
        .fold((0.0, 0usize), |(s, c), (_, p)| {
            (s + p.iter().map(|&v| v as f64).sum::<f64>(), c + 3)
        });
    let variance = sum / count.max(1) as f64;
    let mean_error = compare(mean, reference, mask)?.rmse;
    let bias2 = mean_error * mean_error - variance / n - reference_noise * reference_noise;
    Ok((bias2.max(0.0).sqrt(), variance.sqrt()))
}

/// The Pareto front on (seconds, RMSE): no other run is both faster and better.
fn mark_front(runs: &mut [AccuracyRun]) {
    for i in 0..runs.len() {
        let dominated = runs.iter().enumerate().any(|(j, o)| {
            j != i
                && o.seconds <= runs[i].seconds
                && o.rmse <= runs[i].rmse
                && (o.seconds < runs[i].seconds || o.rmse < runs[i].rmse)
        });
        runs[i].on_pareto_front = !dominated;
    }
}
