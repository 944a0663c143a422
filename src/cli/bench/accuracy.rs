//! `photonmap bench accuracy`: run time against error around a scene's
//! defaults, measured against an SPPM reference (truth, not the paper's
//! estimator agreeing with itself). Each configuration renders several seeds,
//! so its error splits into bias (what more seeds would not remove) and noise
//! (what they would); SPPM runs sit on the same front.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;
use serde::Serialize;

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_atomically;
use photonmap::metrics::compare;
use photonmap::photon::{BuildMethod, GridKind};
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::sppm::{render_sppm, SppmOptions};
use photonmap::render::{
    render, AdaptiveOptions, DifferentialsOptions, EstimateMode, FinalGatherOptions, IgiOptions,
    Image, Kernel, Method, RadiosityOptions, WithCausticMap, WithPhotons,
};
use photonmap::scene::{embedded, Light, Scene};

use super::output::{folder, stem, write_json, BenchOutput};
use super::reference::{read_reference, reference_options, ReferenceInfo};
use super::scene::{default_reference, reference_scale, SEED};

/// `bench accuracy`'s options.
#[derive(Args)]
pub struct AccuracyArgs {
    /// Scene file, or the name of an embedded scene.
    #[arg(long)]
    pub scene: PathBuf,
    /// The SPPM reference (`photonmap reference`; default:
    /// photonmap-out/reference/<scene>.sppm.exr, then
    /// reference_images/<scene>.sppm.exr, under the current folder).
    #[arg(long)]
    pub reference: Option<PathBuf>,
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
    /// "SPPM", "max radius"); repeat it for the runs matching any.
    #[arg(long, value_name = "TEXT")]
    pub only: Vec<String>,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// One configuration's renders against the reference.
#[derive(Serialize, Clone, Debug)]
pub struct AccuracyRun {
    pub label: String,
    /// "paper" (the one-shot kNN estimate), "final-gather", "sppm", "igi" or
    /// "differentials".
    pub method: String,
    pub photons_stored: u32,
    pub k: u32,
    pub max_radius: f32,
    pub leak: LeakTest,
    pub shadow_rays: u32,
    pub build: BuildMethod,
    pub tile: u32,
    pub spp: u32,
    pub sppm_iterations: u32,
    /// Final gather's rays per pixel (0: the one map visualised directly).
    pub gather_rays: u32,
    /// Adaptive sampling of the global light (its default threshold).
    pub adaptive: bool,
    /// The photon map's grid storage: uniform, or hashed (section 4.4).
    pub grid: GridKind,
    /// IGI's options (method "igi").
    pub igi: Option<IgiOptions>,
    /// Photon differentials' options (method "differentials").
    pub differentials: Option<DifferentialsOptions>,
    /// Radiosity's options (method "radiosity").
    pub radiosity: Option<RadiosityOptions>,
    /// Wall seconds of one render (mean over the seeds).
    pub seconds: f64,
    /// RMSE of one render against the reference (mean over the seeds).
    pub rmse: f64,
    /// The part of it more seeds would not remove: the RMSE of the seeds'
    /// mean, less its noise and the reference's.
    pub bias_rmse: f64,
    /// The part they would: the RMS over pixels of one render's standard deviation.
    pub noise_rmse: f64,
    pub rel_mse: f64,
    pub ssim: f64,
    pub on_pareto_front: bool,
}

#[derive(Serialize)]
pub struct AccuracyReport {
    pub scene: String,
    pub reference: ReferenceInfo,
    pub renderer: String,
    pub seeds: u32,
    pub runs: Vec<AccuracyRun>,
    /// The front's fastest run within 10% of the least RMSE.
    pub recommended: String,
    /// `bias.png`'s full scale: a pixel is fully red (blue) where the scene
    /// defaults' mean over the seeds is this much brighter (darker) than the
    /// reference, in luminance. Half the reference's mean luminance.
    pub bias_map_scale: Option<f64>,
    /// `bias.png`, where the scene defaults' run is biased (when it ran).
    #[serde(skip)]
    pub bias_map: Option<Image>,
}

#[derive(Clone)]
struct Config {
    run: AccuracyRun,
}

impl Config {
    fn paper(scene: &Scene) -> Self {
        Self {
            run: AccuracyRun {
                label: "scene defaults".into(),
                method: "paper".into(),
                photons_stored: scene.photon_map.photons_stored,
                k: scene.photon_map.k,
                max_radius: scene.photon_map.max_radius,
                leak: LeakTest::Visibility,
                shadow_rays: scene.render.shadow_rays,
                build: BuildMethod::Bitonic,
                tile: 16,
                spp: 1,
                sppm_iterations: 0,
                gather_rays: 0,
                adaptive: false,
                grid: GridKind::Uniform,
                igi: None,
                differentials: None,
                radiosity: None,
                seconds: 0.0,
                rmse: 0.0,
                bias_rmse: 0.0,
                noise_rmse: 0.0,
                rel_mse: 0.0,
                ssim: 0.0,
                on_pareto_front: false,
            },
        }
    }

    fn with(&self, label: String, f: impl FnOnce(&mut AccuracyRun)) -> Self {
        let mut c = self.clone();
        c.run.label = label;
        f(&mut c.run);
        c
    }

    /// This run by another method, at `spp` eye samples, with its options set by `f`.
    fn by(&self, label: &str, method: &str, spp: u32, f: impl FnOnce(&mut AccuracyRun)) -> Self {
        self.with(label.into(), |r| {
            r.method = method.into();
            r.spp = spp;
            f(r);
        })
    }
}

/// The sweep: one parameter at a time around the scene's defaults, the leak
/// tests, and SPPM at several iteration counts.
fn sweep(scene: &Scene, quick: bool) -> Vec<Config> {
    let base = Config::paper(scene);
    let mut out = vec![base.clone()];
    let factors: &[f32] = if quick {
        &[0.5, 2.0]
    } else {
        &[0.25, 0.5, 2.0, 4.0]
    };
    for &f in factors {
        out.push(base.with(format!("photons x{f}"), |r| {
            r.photons_stored = ((r.photons_stored as f32 * f) as u32).max(16)
        }));
        out.push(base.with(format!("k x{f}"), |r| {
            r.k = ((r.k as f32 * f) as u32).max(1)
        }));
        out.push(base.with(format!("max radius x{f}"), |r| r.max_radius *= f));
    }
    for leak in [LeakTest::None, LeakTest::Disc, LeakTest::DiscAndVisibility] {
        out.push(
            base.with(format!("leak test {leak:?}").to_lowercase(), |r| {
                r.leak = leak
            }),
        );
    }
    if scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Area { .. } | Light::Triangles { .. }))
    {
        for s in if quick { vec![1] } else { vec![1, 16] } {
            if s != base.run.shadow_rays {
                out.push(base.with(format!("{s} shadow rays"), |r| r.shadow_rays = s));
            }
        }
    }
    if !quick {
        out.push(base.with("stencil routing".into(), |r| r.build = BuildMethod::Stencil));
        out.push(base.with("full screen".into(), |r| r.tile = 0));
    }
    for spp in if quick { vec![4] } else { vec![4, 16] } {
        out.push(base.with(format!("{spp} spp"), |r| r.spp = spp));
    }
    // Final gather needs diffuse interreflection, which caustics-only scenes leave out.
    if !scene.photon_map.caustics_only {
        // 16 rays already take 15 times the scene defaults in CORNELL BOX.
        for rays in if quick { vec![4] } else { vec![4, 16] } {
            let label = format!("final gather {rays} rays");
            out.push(base.by(&label, "final-gather", 1, |r| r.gather_rays = rays));
        }
        let label = "final gather 16 rays, adaptive";
        out.push(base.by(label, "final-gather", 1, |r| {
            r.gather_rays = 16;
            r.adaptive = true;
        }));
    }
    out.push(base.with("adaptive".into(), |r| r.adaptive = true));
    out.push(base.with("hash grid".into(), |r| r.grid = GridKind::Hash));
    out.push(base.with("4 spp, adaptive".into(), |r| {
        r.spp = 4;
        r.adaptive = true;
    }));
    for it in if quick {
        vec![4, 16]
    } else {
        vec![4, 16, 64, 256]
    } {
        let label = format!("SPPM {it} iterations");
        out.push(base.by(&label, "sppm", 1, |r| r.sppm_iterations = it));
    }
    out.extend(igi_rows(&base, quick));
    out.extend(differentials_rows(&base, quick));
    // Radiosity solves diffuse interreflection, which caustics-only scenes leave out.
    if !scene.photon_map.caustics_only {
        out.extend(radiosity_rows(&base, quick));
    }
    // Adaptive SPPM (a pilot of an eighth of the iterations, then the
    // gather only where the plan computes), beside the full runs above.
    for it in if quick { vec![16] } else { vec![16, 64] } {
        let label = format!("SPPM {it} iterations, adaptive");
        out.push(base.by(&label, "sppm", 1, |r| {
            r.sppm_iterations = it;
            r.adaptive = true;
        }));
    }
    out
}

/// Instant global illumination: the canonical version, more VPLs, each of
/// Marques and Santos's accelerations alone, all three together, the remedy
/// they suggest for the combination's artefacts (a 2 x 2 interleave), and 4
/// spp (at 1 spp every method's error is mostly aliasing against the
/// antialiased reference).
fn igi_rows(base: &Config, quick: bool) -> Vec<Config> {
    let mut out = Vec::new();
    let igi = |label: &str, f: &dyn Fn(&mut IgiOptions)| {
        base.by(label, "igi", 1, |r| {
            let mut o = IgiOptions::default();
            f(&mut o);
            r.igi = Some(o);
        })
    };
    let all_three = |o: &mut IgiOptions| {
        o.imperfect_visibility = true;
        o.interleave = 3;
        o.downsample = 4;
    };
    out.push(igi("IGI", &|_| {}));
    out.push(igi("IGI, all three accelerations", &all_three));
    if !quick {
        out.push(igi("IGI 256 paths", &|o| o.vpl_paths = 256));
        out.push(igi("IGI, imperfect visibility", &|o| {
            o.imperfect_visibility = true
        }));
        out.push(igi("IGI, downsample 4", &|o| o.downsample = 4));
        out.push(igi("IGI, interleave 3", &|o| o.interleave = 3));
        out.push(igi("IGI, all three, interleave 2", &|o| {
            all_three(o);
            o.interleave = 2;
        }));
        out.push(igi("IGI 256 paths, all three", &|o| {
            all_three(o);
            o.vpl_paths = 256;
        }));
        // At 1 spp every method's error is mostly aliasing against the
        // antialiased reference; 4 spp compares the estimators.
        for (label, f) in [
            (
                "IGI, 4 spp",
                &(|_: &mut IgiOptions| {}) as &dyn Fn(&mut IgiOptions),
            ),
            ("IGI 256 paths, all three, 4 spp", &|o: &mut IgiOptions| {
                all_three(o);
                o.vpl_paths = 256;
            }),
        ] {
            let mut c = igi(label, f);
            c.run.spp = 4;
            out.push(c);
        }
    }
    out
}

/// Photon differentials: automatic smoothing (k_PD = the scene's k), four
/// times the photons, the Epanechnikov kernel, and 4 spp.
fn differentials_rows(base: &Config, quick: bool) -> Vec<Config> {
    let pd = |label: &str, kernel: Kernel, spp: u32| {
        base.by(label, "differentials", spp, |r| {
            r.differentials = Some(DifferentialsOptions {
                kernel,
                ..DifferentialsOptions::default()
            })
        })
    };
    let mut out = vec![pd("differentials", Kernel::Constant, 1)];
    if !quick {
        // The estimate is cheap: more photons at about the kNN-grid's time.
        let mut more = pd("differentials, photons x4", Kernel::Constant, 1);
        more.run.photons_stored *= 4;
        out.push(more);
        out.push(pd("differentials, Epanechnikov", Kernel::Epanechnikov, 1));
        out.push(pd("differentials, 4 spp", Kernel::Constant, 4));
    }
    out
}

/// Progressive radiosity: its defaults, the chapter's ~10,000 elements of
/// CORNELL BOX (32 x 32 a patch side), and 4 spp.
fn radiosity_rows(base: &Config, quick: bool) -> Vec<Config> {
    let rad = |label: &str, resolution: u32, spp: u32| {
        base.by(label, "radiosity", spp, |r| {
            r.radiosity = Some(RadiosityOptions {
                resolution,
                ..RadiosityOptions::default()
            })
        })
    };
    let mut out = vec![rad("radiosity", 16, 1)];
    if !quick {
        out.push(rad("radiosity, 32 elements", 32, 1));
        out.push(rad("radiosity, 4 spp", 16, 4));
    }
    out
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
    let gpu = crate::cli::gpu(platform)?;
    let seeds = a.seeds.unwrap_or(if a.quick { 2 } else { 4 });
    let report = bench_accuracy(
        &gpu,
        &scene,
        &reference,
        a.quick,
        seeds,
        &a.only,
        &a.output.progress(),
    )?;
    let dir = folder(a.out.as_deref(), "accuracy", Some(&stem(&a.scene)))?;
    let write = |name: &str, bytes: &[u8]| write_atomically(&dir.join(name), bytes);
    write("accuracy.csv", csv(&report).as_bytes())?;
    write_json(&dir.join("accuracy.json"), &report)?;
    write("accuracy.svg", svg_plot(&report).as_bytes())?;
    write("accuracy.png", &png_plot(&report))?;
    if let Some(map) = &report.bias_map {
        write("bias.png", &map.png_bytes()?)?;
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
    gi.final_gather = (c.gather_rays > 0).then(|| FinalGatherOptions {
        rays: c.gather_rays,
        ..FinalGatherOptions::default()
    });
    gi.adaptive = c.adaptive.then(AdaptiveOptions::default);
    let map = gi.clone();
    o.method = match (&c.igi, &c.differentials, &c.radiosity) {
        (Some(i), _, _) => Method::Igi(WithCausticMap::from_map(map, i.clone())),
        (_, Some(d), _) => Method::Differentials(WithPhotons::from_map(map, d.clone())),
        (_, _, Some(r)) => Method::Radiosity(WithCausticMap::from_map(map, r.clone())),
        _ => Method::PhotonMap(map),
    };
    let wall = std::time::Instant::now();
    let image = if c.method == "sppm" {
        let sppm = SppmOptions {
            iterations: c.sppm_iterations,
            adaptive: c.adaptive.then(AdaptiveOptions::default),
            ..SppmOptions::default()
        };
        render_sppm(gpu, &s, &o, &sppm, &mut ())?.image
    } else {
        render(gpu, &s, &o, &mut ())?.image
    };
    Ok((image, wall.elapsed().as_secs_f64()))
}

pub fn bench_accuracy(
    gpu: &Gpu,
    scene: &Scene,
    reference: &Path,
    quick: bool,
    seeds: u32,
    only: &[String],
    progress: &dyn Fn(&str),
) -> Result<AccuracyReport> {
    let (reference_img, info) = read_reference(reference)?;
    let scale = reference_scale(reference, &reference_img, scene)?;
    let mut configs = sweep(scene, quick);
    if !only.is_empty() {
        let labels: Vec<String> = configs.iter().map(|c| c.run.label.clone()).collect();
        configs.retain(|c| only.iter().any(|text| c.run.label.contains(text.as_str())));
        if configs.is_empty() {
            bail!(
                "--only {only:?} matches no run; the runs are: {}",
                labels.join(", ")
            );
        }
    }
    let mut runs = Vec::new();
    let mut bias = None;
    for (i, c) in configs.iter().enumerate() {
        progress(&format!("{} ({}/{})", c.run.label, i + 1, configs.len()));
        let mut images = Vec::new();
        let mut seconds = 0.0;
        for seed in 0..seeds {
            let (img, s) = render_config(gpu, scene, &c.run, scale, SEED + seed)?;
            images.push(img);
            seconds += s;
        }
        let mean = Image::average(&images);
        let split = bias_and_noise(&images, &mean, &reference_img, info.residual_noise_rmse)?;
        let one: Vec<_> = images
            .iter()
            .map(|img| compare(img, &reference_img, None))
            .collect::<Result<_, _>>()?;
        let n = images.len() as f64;
        let mut run = c.run.clone();
        run.seconds = seconds / n;
        run.rmse = one.iter().map(|m| m.rmse).sum::<f64>() / n;
        run.rel_mse = one.iter().map(|m| m.rel_mse).sum::<f64>() / n;
        run.ssim = one.iter().map(|m| m.ssim).sum::<f64>() / n;
        (run.bias_rmse, run.noise_rmse) = split;
        if run.label == "scene defaults" {
            bias = Some(bias_map(&mean, &reference_img));
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
        scene: scene.name.clone(),
        reference: info,
        renderer: gpu.capabilities().gl_renderer,
        seeds,
        runs,
        recommended,
        bias_map_scale: bias.as_ref().map(|b| b.1),
        bias_map: bias.map(|b| b.0),
    })
}

/// Where `mean` is biased against `reference`: the reference in dim grey,
/// turning red where the mean is brighter and blue where it is darker, fully
/// at a luminance difference of the returned scale (half the reference's
/// mean luminance).
fn bias_map(mean: &Image, reference: &Image) -> (Image, f64) {
    let [wr, wg, wb] = photonmap::layout::LUMINANCE;
    let luminance = |p: &[f32; 3]| wr * p[0] + wg * p[1] + wb * p[2];
    let mean_luminance =
        reference.pixels.iter().map(luminance).sum::<f32>() / reference.pixels.len().max(1) as f32;
    let scale = if mean_luminance > 0.0 {
        0.5 * mean_luminance
    } else {
        1.0
    };
    let mut out = Image::new(reference.width, reference.height);
    for ((o, m), r) in out
        .pixels
        .iter_mut()
        .zip(&mean.pixels)
        .zip(&reference.pixels)
    {
        let grey = 0.15 * (luminance(r) / (4.0 * scale)).clamp(0.0, 1.0);
        let d = (luminance(m) - luminance(r)) / scale;
        let t = d.abs().clamp(0.0, 1.0);
        let colour = if d > 0.0 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 0.2, 1.0]
        };
        *o = colour.map(|c| grey * (1.0 - t) + c * t);
    }
    (out, scale as f64)
}

/// Bias and noise of one render, as RMS over pixels: noise from the per-pixel
/// spread of the seeds, bias from the seeds' mean against the reference with
/// the mean's own noise and the reference's removed.
fn bias_and_noise(
    images: &[Image],
    mean: &Image,
    reference: &Image,
    reference_noise: f64,
) -> Result<(f64, f64)> {
    let n = images.len() as f64;
    // The per-pixel sample variance (photonmap::regress), averaged over channels.
    let var = photonmap::regress::variance(images, mean);
    let variance =
        var.pixels.iter().flatten().map(|&v| v as f64).sum::<f64>() / (var.pixels.len() * 3) as f64;
    let mean_error = photonmap::metrics::rmse(mean, reference)?;
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

pub fn csv(r: &AccuracyReport) -> String {
    let mut s = String::from("label,method,photons_stored,k,max_radius,leak,shadow_rays,build,grid,tile,spp,sppm_iterations,gather_rays,adaptive,vpl_paths,imperfect_visibility,interleave,downsample,seconds,rmse,bias_rmse,noise_rmse,rel_mse,ssim,pareto\n");
    for x in &r.runs {
        let igi = x.igi.clone().unwrap_or(IgiOptions {
            vpl_paths: 0,
            ..IgiOptions::default()
        });
        s += &format!(
            "{},{},{},{},{},{:?},{},{:?},{:?},{},{},{},{},{},{},{},{},{},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6},{}\n",
            x.label,
            x.method,
            x.photons_stored,
            x.k,
            x.max_radius,
            x.leak,
            x.shadow_rays,
            x.build,
            x.grid,
            x.tile,
            x.spp,
            x.sppm_iterations,
            x.gather_rays,
            x.adaptive,
            igi.vpl_paths,
            igi.imperfect_visibility,
            igi.interleave,
            igi.downsample,
            x.seconds,
            x.rmse,
            x.bias_rmse,
            x.noise_rmse,
            x.rel_mse,
            x.ssim,
            x.on_pareto_front
        );
    }
    s
}

/// Each run's log10 seconds and log10 RMSE (floored above zero): the points
/// both plots draw.
fn log_points(r: &AccuracyReport) -> (Vec<f64>, Vec<f64>) {
    let xs = r.runs.iter().map(|x| x.seconds.max(1e-4).log10());
    let ys = r.runs.iter().map(|x| x.rmse.max(1e-9).log10());
    (xs.collect(), ys.collect())
}

/// RMSE against seconds, log-log, the Pareto front joined.
pub fn svg_plot(r: &AccuracyReport) -> String {
    let mut plot = super::plot::LogLog::new(
        &format!(
            "{}: RMSE against the SPPM reference, by run time (log-log)",
            r.scene
        ),
        "seconds per render (wall clock)",
        "RMSE of one render (bias and noise)",
    );
    let point = |x: &AccuracyRun| (x.seconds, x.rmse, x.label.clone());
    let front = r
        .runs
        .iter()
        .filter(|x| x.on_pareto_front)
        .map(point)
        .collect();
    plot.points("#d62728", front, true);
    for (method, colour) in [
        ("sppm", "#2ca02c"),
        ("igi", "#9467bd"),
        ("differentials", "#ff7f0e"),
        ("radiosity", "#8c564b"),
        ("photon map", "#1f77b4"),
    ] {
        let kind = |m: &str| match m {
            "sppm" | "igi" | "differentials" | "radiosity" => m.to_string(),
            _ => "photon map".into(),
        };
        let others = r
            .runs
            .iter()
            .filter(|x| !x.on_pareto_front && kind(&x.method) == method)
            .map(point)
            .collect();
        plot.points(colour, others, false);
    }
    plot.svg()
}

/// The same plot as a PNG: points and the front on log-log axes (no text; the SVG has the labels).
pub fn png_plot(r: &AccuracyReport) -> Vec<u8> {
    let (w, h, m) = (480u32, 320u32, 30.0f64);
    let mut img = image::RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]));
    let (xs, ys) = log_points(r);
    let (x0, x1) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min) - 0.1,
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.1,
    );
    let (y0, y1) = (
        ys.iter().copied().fold(f64::INFINITY, f64::min) - 0.1,
        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.1,
    );
    let px = |x: f64| (m + (x - x0) / (x1 - x0) * (w as f64 - 2.0 * m)) as i64;
    let py = |y: f64| (h as f64 - m - (y - y0) / (y1 - y0) * (h as f64 - 2.0 * m)) as i64;
    let mut put = |x: i64, y: i64, c: [u8; 3]| {
        if x >= 0 && y >= 0 && (x as u32) < w && (y as u32) < h {
            img.put_pixel(x as u32, y as u32, image::Rgb(c));
        }
    };
    for x in m as i64..(w as i64 - m as i64) {
        put(x, h as i64 - m as i64, [0, 0, 0]);
    }
    for y in m as i64..(h as i64 - m as i64) {
        put(m as i64, y, [0, 0, 0]);
    }
    let mut front: Vec<usize> = (0..r.runs.len())
        .filter(|&i| r.runs[i].on_pareto_front)
        .collect();
    front.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    for pair in front.windows(2) {
        let (ax, ay, bx, by) = (
            px(xs[pair[0]]),
            py(ys[pair[0]]),
            px(xs[pair[1]]),
            py(ys[pair[1]]),
        );
        let steps = (bx - ax).abs().max((by - ay).abs()).max(1);
        for t in 0..=steps {
            put(
                ax + (bx - ax) * t / steps,
                ay + (by - ay) * t / steps,
                [214, 39, 40],
            );
        }
    }
    for (i, run) in r.runs.iter().enumerate() {
        let c = match (run.on_pareto_front, run.method.as_str()) {
            (true, _) => [214, 39, 40],
            (false, "sppm") => [44, 160, 44],
            (false, "igi") => [148, 103, 189],
            (false, "differentials") => [255, 127, 14],
            (false, "radiosity") => [140, 86, 75],
            _ => [31, 119, 180],
        };
        for dy in -3..=3i64 {
            for dx in -3..=3i64 {
                if dx * dx + dy * dy <= 9 {
                    put(px(xs[i]) + dx, py(ys[i]) + dy, c);
                }
            }
        }
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("encoding a PNG in memory");
    out.into_inner()
}
