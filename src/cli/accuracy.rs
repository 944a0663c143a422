//! `photonmap reference` (a converged reference made by this project's own
//! pipeline) and `photonmap bench accuracy` (run time against error around a
//! scene's defaults, and the Pareto front).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::{Deserialize, Serialize};

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_atomically;
use photonmap::metrics::{compare, Metrics};
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::render::{render, EstimateMode, GlobalIllumination, Image, RenderOptions};
use photonmap::scene::{embedded, Scene};

/// Render a converged reference of a scene (more photons, larger k, several
/// eye samples, many seeds averaged) as EXR, with its command and residual noise.
#[derive(Args)]
pub struct ReferenceArgs {
    /// Scene file, or the name of an embedded scene.
    pub scene: PathBuf,
    /// Output EXR (default: reference_images/<scene>.converged.exr under the
    /// current folder; a .json goes beside it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Render at 1/scale of the scene's resolution (1..=16).
    #[arg(long, default_value_t = 2, value_parser = super::args::in_range(1, 16))]
    pub scale: u32,
    /// Photons stored x this; k x its square root (1..=64).
    #[arg(long, default_value_t = 8, value_parser = super::args::in_range(1, 64))]
    pub photons_factor: u32,
    /// Renders averaged (2..=256).
    #[arg(long, default_value_t = 8, value_parser = super::args::in_range(2, 256))]
    pub seeds: u32,
    /// Eye samples per pixel of each (1..=256).
    #[arg(long, default_value_t = 4, value_parser = super::args::in_range(1, 256))]
    pub spp: u32,
}

pub fn run_reference(a: &ReferenceArgs, platform: Platform) -> Result<()> {
    let scene = embedded::load_path_or_name(&a.scene)?;
    let out = a.out.clone().unwrap_or_else(|| default_reference(&a.scene));
    super::check_output(&out, "exr", "--out")?;
    let gpu = super::gpu(platform)?;
    let command = format!(
        "photonmap reference {} --scale {} --photons-factor {} --seeds {} --spp {}",
        a.scene.display(),
        a.scale,
        a.photons_factor,
        a.seeds,
        a.spp
    );
    let options = ReferenceOptions {
        scale: a.scale,
        photons_factor: a.photons_factor,
        seeds: a.seeds,
        spp: a.spp,
    };
    let (img, info) = make_reference(&gpu, &scene, &options, command, &|m: &str| eprintln!("{m}"))?;
    write_reference(&img, &info, &out)?;
    eprintln!(
        "wrote {} (residual RMSE {:.6})",
        out.display(),
        info.residual_rmse
    );
    Ok(())
}

/// `bench accuracy`'s options.
#[derive(Args)]
pub struct AccuracyArgs {
    /// Scene file, or the name of an embedded scene.
    #[arg(long)]
    pub scene: PathBuf,
    /// The converged reference (default: reference_images/<scene>.converged.exr
    /// under the current folder).
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// Output folder (default: results/<renderer>/accuracy/<scene>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A small sweep.
    #[arg(long)]
    pub quick: bool,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

pub fn run_bench(a: &AccuracyArgs, platform: Platform) -> Result<()> {
    let scene = embedded::load_path_or_name(&a.scene)?;
    let reference = a
        .reference
        .clone()
        .unwrap_or_else(|| default_reference(&a.scene));
    if !reference.is_file() {
        bail!(
            "no converged reference at {}: make one with `photonmap reference {}`",
            reference.display(),
            a.scene.display()
        );
    }
    let gpu = super::gpu(platform)?;
    let report = bench_accuracy(
        &gpu,
        &scene,
        &reference,
        a.quick,
        &super::progress_lines(a.quiet),
    )?;
    let dir = a.out.clone().unwrap_or_else(|| {
        super::tables::default_out(&report.renderer)
            .join("accuracy")
            .join(stem(&a.scene))
    });
    std::fs::create_dir_all(&dir)?;
    let write = |name: &str, bytes: &[u8]| write_atomically(&dir.join(name), bytes);
    write("accuracy.csv", csv(&report).as_bytes())?;
    write(
        "accuracy.json",
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )?;
    write("accuracy.svg", svg_plot(&report).as_bytes())?;
    write("accuracy.png", &png_plot(&report))?;
    if a.json {
        return super::print_json(&report);
    }
    println!(
        "{:<18} {:>9} {:>11} {:>8} {:>7}",
        "run", "seconds", "rel. MSE", "SSIM", "front"
    );
    for r in &report.runs {
        println!(
            "{:<18} {:>9.3} {:>11.5} {:>8.4} {:>7}",
            r.label,
            r.total_seconds,
            r.metrics.rel_mse,
            r.metrics.ssim,
            if r.on_pareto_front { "*" } else { "" }
        );
    }
    println!("recommended: {}", report.recommended);
    eprintln!("wrote {}", dir.display());
    Ok(())
}

fn stem(scene: &Path) -> String {
    scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

#[derive(Serialize, Deserialize, Debug, Clone)]
pub struct ReferenceInfo {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub photons_stored: u32,
    pub k: u32,
    pub max_radius: f32,
    pub spp: u32,
    pub seeds: u32,
    /// RMSE between the means of the even and the odd seeds, halved: the
    /// residual noise of the full mean.
    pub residual_rmse: f64,
    pub command: String,
    pub renderer: String,
}

pub struct ReferenceOptions {
    pub scale: u32,
    pub photons_factor: u32,
    pub seeds: u32,
    pub spp: u32,
}

/// Renders the converged reference: photons x factor, k x sqrt(factor) (the
/// radius shrinks as the density grows, so bias falls with the noise), spp
/// eye samples, `seeds` renders averaged.
pub fn make_reference(
    gpu: &Gpu,
    scene: &Scene,
    o: &ReferenceOptions,
    command: String,
    progress: &dyn Fn(&str),
) -> Result<(Image, ReferenceInfo)> {
    let mut s = scene.clone();
    s.photon_map.photons_stored = scene
        .photon_map
        .photons_stored
        .saturating_mul(o.photons_factor);
    s.photon_map.k =
        ((scene.photon_map.k as f64) * (o.photons_factor as f64).sqrt()).round() as u32;
    let mut images = Vec::new();
    for seed in 1..=o.seeds {
        progress(&format!(
            "reference {}: seed {seed}/{}",
            scene.name, o.seeds
        ));
        let mut opts = RenderOptions::for_scene(&s);
        opts.width = (scene.camera.width / o.scale).max(1);
        opts.height = (scene.camera.height / o.scale).max(1);
        opts.spp = o.spp;
        opts.seed = 1000 + seed;
        images.push(render(gpu, &s, &opts, &mut ())?.image);
    }
    let even: Vec<Image> = images.iter().step_by(2).cloned().collect();
    let odd: Vec<Image> = images.iter().skip(1).step_by(2).cloned().collect();
    let residual = compare(&Image::average(&even), &Image::average(&odd), None)?.rmse / 2.0;
    let img = Image::average(&images);
    let info = ReferenceInfo {
        scene: scene.name.clone(),
        width: img.width,
        height: img.height,
        photons_stored: s.photon_map.photons_stored,
        k: s.photon_map.k,
        max_radius: s.photon_map.max_radius,
        spp: o.spp,
        seeds: o.seeds,
        residual_rmse: residual,
        command,
        renderer: gpu.capabilities().gl_renderer,
    };
    Ok((img, info))
}

pub fn write_reference(img: &Image, info: &ReferenceInfo, exr: &Path) -> Result<()> {
    write_atomically(exr, &img.exr_bytes()?)?;
    write_atomically(
        &exr.with_extension("json"),
        (serde_json::to_string_pretty(info)? + "\n").as_bytes(),
    )?;
    Ok(())
}

#[derive(Serialize, Clone, Debug)]
pub struct AccuracyRun {
    pub label: String,
    pub photons_stored: u32,
    pub k: u32,
    pub max_radius: f32,
    pub shadow_rays: u32,
    pub build: BuildMethod,
    pub tile: u32,
    pub spp: u32,
    pub trace_photons_seconds: f64,
    pub build_map_seconds: f64,
    pub trace_rays_seconds: f64,
    pub radiance_estimate_seconds: f64,
    pub total_seconds: f64,
    pub metrics: Metrics,
    pub on_pareto_front: bool,
}

#[derive(Serialize)]
pub struct AccuracyReport {
    pub scene: String,
    pub reference: ReferenceInfo,
    pub renderer: String,
    pub runs: Vec<AccuracyRun>,
    /// The front's run with the least relative MSE per second spent, or the fastest within 10% of the best error.
    pub recommended: String,
}

#[derive(Clone)]
struct Config {
    label: String,
    photons_stored: u32,
    k: u32,
    max_radius: f32,
    shadow_rays: u32,
    build: BuildMethod,
    tile: u32,
    spp: u32,
}

fn sweep(scene: &Scene, quick: bool) -> Vec<Config> {
    let base = Config {
        label: "scene defaults".into(),
        photons_stored: scene.photon_map.photons_stored,
        k: scene.photon_map.k,
        max_radius: scene.photon_map.max_radius,
        shadow_rays: scene.render.shadow_rays,
        build: BuildMethod::Bitonic,
        tile: 16,
        spp: 1,
    };
    let mut out = vec![base.clone()];
    let factors: &[f32] = if quick {
        &[0.5, 2.0]
    } else {
        &[0.25, 0.5, 2.0, 4.0]
    };
    for &f in factors {
        out.push(Config {
            label: format!("photons x{f}"),
            photons_stored: ((base.photons_stored as f32 * f) as u32).max(16),
            ..base.clone()
        });
        out.push(Config {
            label: format!("k x{f}"),
            k: ((base.k as f32 * f) as u32).max(1),
            ..base.clone()
        });
        out.push(Config {
            label: format!("max radius x{f}"),
            max_radius: base.max_radius * f,
            ..base.clone()
        });
    }
    let has_area = scene
        .lights
        .iter()
        .any(|l| matches!(l, photonmap::scene::Light::Area { .. }));
    if has_area {
        for s in if quick { vec![1] } else { vec![1, 16] } {
            if s != base.shadow_rays {
                out.push(Config {
                    label: format!("{s} shadow rays"),
                    shadow_rays: s,
                    ..base.clone()
                });
            }
        }
    }
    out.push(Config {
        label: "stencil routing".into(),
        build: BuildMethod::Stencil,
        ..base.clone()
    });
    out.push(Config {
        label: "full screen".into(),
        tile: 0,
        ..base.clone()
    });
    for spp in if quick { vec![4] } else { vec![4, 16] } {
        out.push(Config {
            label: format!("{spp} spp"),
            spp,
            ..base.clone()
        });
    }
    out
}

pub fn bench_accuracy(
    gpu: &Gpu,
    scene: &Scene,
    reference: &Path,
    quick: bool,
    progress: &dyn Fn(&str),
) -> Result<AccuracyReport> {
    let reference_img = Image::read_exr(reference)?;
    let info: ReferenceInfo = serde_json::from_str(
        &std::fs::read_to_string(reference.with_extension("json"))
            .with_context(|| format!("reading {}", reference.with_extension("json").display()))?,
    )
    .context("the reference's JSON")?;
    let configs = sweep(scene, quick);
    let mut runs = Vec::new();
    for (i, c) in configs.iter().enumerate() {
        progress(&format!("{} ({}/{})", c.label, i + 1, configs.len()));
        let mut s = scene.clone();
        s.photon_map.photons_stored = c.photons_stored;
        s.photon_map.k = c.k;
        s.photon_map.max_radius = c.max_radius;
        s.render.shadow_rays = c.shadow_rays;
        let mut o = RenderOptions::for_scene(&s);
        (o.width, o.height, o.spp, o.seed) = (reference_img.width, reference_img.height, c.spp, 7);
        let mut gi = GlobalIllumination {
            photons: PhotonConfig {
                build: c.build,
                ..PhotonConfig::default()
            },
            ..GlobalIllumination::default()
        };
        gi.estimate.mode = if c.tile == 0 {
            EstimateMode::FullScreen
        } else {
            EstimateMode::Tiled { tile: c.tile }
        };
        o.global = Some(gi);
        let r = render(gpu, &s, &o, &mut ())?;
        let stage = |names: &[&str]| {
            r.timings
                .stages
                .iter()
                .filter(|st| names.contains(&st.name.as_str()))
                .map(|st| st.wall_seconds)
                .sum::<f64>()
        };
        let metrics = compare(&r.image, &reference_img, None)?;
        let (tp, bm, tr, re) = (
            stage(&["trace photons"]),
            stage(&["build map"]),
            stage(&["eye rays", "intersect", "shadow rays", "specular"]),
            stage(&["radiance estimate"]),
        );
        runs.push(AccuracyRun {
            label: c.label.clone(),
            photons_stored: c.photons_stored,
            k: c.k,
            max_radius: c.max_radius,
            shadow_rays: c.shadow_rays,
            build: c.build,
            tile: c.tile,
            spp: c.spp,
            trace_photons_seconds: tp,
            build_map_seconds: bm,
            trace_rays_seconds: tr,
            radiance_estimate_seconds: re,
            total_seconds: tp + bm + tr + re,
            metrics,
            on_pareto_front: false,
        });
    }
    // Pareto front on (total seconds, relative MSE): no other run is both faster and better.
    for i in 0..runs.len() {
        let dominated = runs.iter().enumerate().any(|(j, o)| {
            j != i
                && o.total_seconds <= runs[i].total_seconds
                && o.metrics.rel_mse <= runs[i].metrics.rel_mse
                && (o.total_seconds < runs[i].total_seconds
                    || o.metrics.rel_mse < runs[i].metrics.rel_mse)
        });
        runs[i].on_pareto_front = !dominated;
    }
    let best = runs
        .iter()
        .map(|r| r.metrics.rel_mse)
        .fold(f64::INFINITY, f64::min);
    let recommended = runs
        .iter()
        .filter(|r| r.on_pareto_front && r.metrics.rel_mse <= best * 1.1)
        .min_by(|a, b| a.total_seconds.total_cmp(&b.total_seconds))
        .map(|r| r.label.clone())
        .unwrap_or_default();
    Ok(AccuracyReport {
        scene: scene.name.clone(),
        reference: info,
        renderer: gpu.capabilities().gl_renderer,
        runs,
        recommended,
    })
}

pub fn csv(r: &AccuracyReport) -> String {
    let mut s = String::from("label,photons_stored,k,max_radius,shadow_rays,build,tile,spp,trace_photons_s,build_map_s,trace_rays_s,radiance_estimate_s,total_s,rmse,rel_mse,ssim,pareto\n");
    for x in &r.runs {
        s += &format!(
            "{},{},{},{},{},{:?},{},{},{:.4},{:.4},{:.4},{:.4},{:.4},{:.6},{:.6},{:.6},{}\n",
            x.label,
            x.photons_stored,
            x.k,
            x.max_radius,
            x.shadow_rays,
            x.build,
            x.tile,
            x.spp,
            x.trace_photons_seconds,
            x.build_map_seconds,
            x.trace_rays_seconds,
            x.radiance_estimate_seconds,
            x.total_seconds,
            x.metrics.rmse,
            x.metrics.rel_mse,
            x.metrics.ssim,
            x.on_pareto_front
        );
    }
    s
}

/// Each run's log10 seconds and log10 relative MSE (floored above zero): the
/// points both plots draw.
fn log_points(r: &AccuracyReport) -> (Vec<f64>, Vec<f64>) {
    let xs = r.runs.iter().map(|x| x.total_seconds.max(1e-4).log10());
    let ys = r.runs.iter().map(|x| x.metrics.rel_mse.max(1e-9).log10());
    (xs.collect(), ys.collect())
}

/// Relative MSE against seconds, log-log, the Pareto front joined: an SVG
/// written by hand (plotters' text needs system fonts CI may lack).
pub fn svg_plot(r: &AccuracyReport) -> String {
    let (w, h, m) = (720.0, 480.0, 70.0);
    let (xs, ys) = log_points(r);
    let (x0, x1) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min).floor(),
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil(),
    );
    let (y0, y1) = (
        ys.iter().copied().fold(f64::INFINITY, f64::min).floor(),
        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max).ceil(),
    );
    let (x1, y1) = (
        if x1 <= x0 { x0 + 1.0 } else { x1 },
        if y1 <= y0 { y0 + 1.0 } else { y1 },
    );
    let px = |x: f64| m + (x - x0) / (x1 - x0) * (w - 2.0 * m);
    let py = |y: f64| h - m - (y - y0) / (y1 - y0) * (h - 2.0 * m);
    let mut s = format!("<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n");
    s += &format!("<text x=\"{}\" y=\"22\" font-size=\"15\" text-anchor=\"middle\">{}: relative MSE against run time (log-log)</text>\n", w / 2.0, r.scene);
    s += &format!("<line x1=\"{m}\" y1=\"{}\" x2=\"{}\" y2=\"{}\" stroke=\"black\"/>\n<line x1=\"{m}\" y1=\"{m}\" x2=\"{m}\" y2=\"{}\" stroke=\"black\"/>\n", h - m, w - m, h - m, h - m);
    for d in x0 as i64..=x1 as i64 {
        let x = px(d as f64);
        s += &format!("<line x1=\"{x}\" y1=\"{}\" x2=\"{x}\" y2=\"{}\" stroke=\"black\"/><text x=\"{x}\" y=\"{}\" text-anchor=\"middle\">{} s</text>\n", h - m, h - m + 5.0, h - m + 18.0, 10f64.powi(d as i32));
    }
    for d in y0 as i64..=y1 as i64 {
        let y = py(d as f64);
        s += &format!("<line x1=\"{}\" y1=\"{y}\" x2=\"{m}\" y2=\"{y}\" stroke=\"black\"/><text x=\"{}\" y=\"{}\" text-anchor=\"end\">1e{d}</text>\n", m - 5.0, m - 8.0, y + 4.0);
    }
    s += &format!("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">total seconds (trace photons + build map + trace rays + estimate)</text>\n", w / 2.0, h - 20.0);
    s += &format!("<text x=\"18\" y=\"{}\" transform=\"rotate(-90 18 {})\" text-anchor=\"middle\">relative MSE against the converged reference</text>\n", h / 2.0, h / 2.0);
    let mut front: Vec<usize> = (0..r.runs.len())
        .filter(|&i| r.runs[i].on_pareto_front)
        .collect();
    front.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    let path: Vec<String> = front
        .iter()
        .map(|&i| format!("{:.1},{:.1}", px(xs[i]), py(ys[i])))
        .collect();
    s += &format!(
        "<polyline points=\"{}\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"1.5\"/>\n",
        path.join(" ")
    );
    for (i, run) in r.runs.iter().enumerate() {
        let colour = if run.on_pareto_front {
            "#d62728"
        } else {
            "#1f77b4"
        };
        s += &format!(
            "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\" fill=\"{colour}\"/><text x=\"{:.1}\" y=\"{:.1}\" font-size=\"9\">{}</text>\n",
            px(xs[i]),
            py(ys[i]),
            px(xs[i]) + 6.0,
            py(ys[i]) - 5.0,
            run.label
        );
    }
    s + "</svg>\n"
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
        let c = if run.on_pareto_front {
            [214, 39, 40]
        } else {
            [31, 119, 180]
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

/// reference_images/<scene>.converged.exr under the current folder.
pub fn default_reference(scene: &Path) -> PathBuf {
    PathBuf::from("reference_images").join(format!("{}.converged.exr", stem(scene)))
}
