//! `photonmap regress`: image regression for CI in one command. Renders each
//! scene at its reference's size, runs the per-pixel z-test against the
//! reference's mean and variance, prints a verdict, and on failure writes the
//! image, the reference and the error map. JSON, and one JUnit XML and one
//! HTML report for all the scenes.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_all_atomically;
use photonmap::metrics::{false_colour, flip_map, FLIP_PERCENTILES};
use photonmap::regress::{make_reference, Reference, Tolerance};
use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::Scene;

use super::args::{in_range, key_value, LoadedScene, SceneArgs};
use super::ci_report::{self, Case, Picture};

/// Render scenes and test each against its regression reference (the z-test
/// of tests/gpu/reference_images.rs); --update makes the references instead.
#[derive(Args)]
pub struct RegressArgs {
    /// Scene files or embedded scene names, one or more; each has its
    /// reference in --reference under its file's stem.
    #[arg(required = true, value_name = "SCENE")]
    pub scenes: Vec<PathBuf>,
    /// Override a field of every scene, as render's --set (repeatable).
    #[arg(long = "set", short = 'D', value_name = "KEY=VALUE", value_parser = key_value)]
    pub set: Vec<(String, String)>,
    /// pbrt and Mitsuba scenes: map what photonmap cannot render to the
    /// nearest thing it can, as render's --lenient, instead of refusing it.
    #[arg(long)]
    pub lenient: bool,
    /// The folder of the references: <scene>.exr (mean), <scene>.var.exr, <scene>.json.
    #[arg(long, value_name = "DIR")]
    pub reference: PathBuf,
    /// The reference's name in the folder (default: the scene file's stem; one scene only).
    #[arg(long)]
    pub name: Option<String>,
    /// The render's seed (the reference is made from seeds 1..=N; keep it out of them).
    #[arg(long, default_value_t = 1000)]
    pub seed: u32,
    /// Direct light and specular paths only (a render without its photon map).
    #[arg(long)]
    pub direct_only: bool,
    /// Where images go when a test fails (default: photonmap-out/regress/<name>/;
    /// with several scenes, <DIR>/<name>/).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Make (or remake) the references from --seeds renders at --width x --height.
    #[arg(long)]
    pub update: bool,
    /// --update: renders averaged (3..=256).
    #[arg(long, default_value_t = 16, value_parser = in_range(3, 256))]
    pub seeds: u32,
    /// --update: the reference's width (default: a quarter of the scene's).
    #[arg(long, value_parser = in_range(1, 16384))]
    pub width: Option<u32>,
    /// --update: the reference's height (default: a quarter of the scene's).
    #[arg(long, value_parser = in_range(1, 16384))]
    pub height: Option<u32>,
    /// Print the verdict as JSON on stdout (an array with several scenes).
    #[arg(long)]
    pub json: bool,
    /// Also write a JUnit XML report, one test case per scene, to this file.
    #[arg(long, value_name = "XML")]
    pub junit: Option<PathBuf>,
    /// Also write an HTML report to this file: per scene the render, the
    /// reference, FLIP's error map and the |z| map side by side, with the
    /// figures (self-contained).
    #[arg(long, value_name = "HTML")]
    pub html: Option<PathBuf>,
    #[arg(long)]
    pub quiet: bool,
}

#[derive(serde::Serialize)]
struct Verdict {
    scene: String,
    reference: String,
    passed: bool,
    /// Fraction of pixel channels beyond |z| = 4, and the tolerance.
    failing_fraction: f64,
    tolerance: f64,
    /// FLIP's mean and weighted percentiles against the reference's mean.
    flip: f64,
    flip_percentiles: std::collections::BTreeMap<String, f64>,
    seed: u32,
    seconds: f64,
    provenance: photonmap::provenance::Provenance,
    images: Vec<String>,
}

/// A scene to test: its arguments, loaded scene and reference name.
struct Job {
    args: SceneArgs,
    loaded: LoadedScene,
    name: String,
}

fn options(scene: &Scene, width: u32, height: u32, seed: u32, direct_only: bool) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (width, height, seed);
    if direct_only {
        o = o.direct_only();
    }
    o
}

/// Every scene loaded, before any render: a bad one refuses the whole run.
fn jobs(a: &RegressArgs) -> Result<Vec<Job>> {
    if a.name.is_some() && a.scenes.len() > 1 {
        bail!("--name names one reference; give one scene with it");
    }
    a.scenes
        .iter()
        .map(|scene| {
            let args = SceneArgs {
                scene: scene.clone(),
                set: a.set.clone(),
                lenient: a.lenient,
            };
            let loaded = args.load()?;
            let name = a.name.clone().unwrap_or_else(|| {
                scene
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default()
            });
            Ok(Job { args, loaded, name })
        })
        .collect()
}

pub fn run(a: &RegressArgs, platform: Platform) -> Result<()> {
    if a.update && (a.junit.is_some() || a.html.is_some()) {
        bail!("--junit and --html report a test; --update makes references and tests nothing");
    }
    ci_report::check_paths(a.junit.as_deref(), a.html.as_deref())?;
    let jobs = jobs(a)?;
    let gpu = super::gpu(platform)?;
    if a.update {
        for job in &jobs {
            update(a, &gpu, job)?;
        }
        return Ok(());
    }
    let references = jobs
        .iter()
        .map(|j| Ok(Reference::load(&a.reference, &j.name)?))
        .collect::<Result<Vec<_>>>()?;
    let (mut verdicts, mut cases) = (Vec::new(), Vec::new());
    for (job, reference) in jobs.iter().zip(&references) {
        let (verdict, case) = test(a, &gpu, job, reference, jobs.len() > 1)?;
        if !a.json && !a.quiet {
            print_line(&verdict);
        }
        verdicts.push(verdict);
        cases.push(case);
    }
    if a.json {
        match verdicts.as_slice() {
            [one] => super::print_json(one)?,
            all => super::print_json(&all)?,
        }
    }
    let files = ci_report::files("regress", &cases, a.junit.as_deref(), a.html.as_deref())?;
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    write_all_atomically(&refs)?;
    let failed: Vec<String> = jobs
        .iter()
        .zip(&verdicts)
        .filter(|(_, v)| !v.passed)
        .map(|(j, v)| {
            format!(
                "{}: {:.4}% of channels beyond |z| = 4, tolerance {:.4}%: images in {}",
                j.name,
                100.0 * v.failing_fraction,
                100.0 * v.tolerance,
                folder_of(&v.images)
            )
        })
        .collect();
    if !failed.is_empty() {
        bail!("{}", failed.join("; "));
    }
    Ok(())
}

fn folder_of(images: &[String]) -> String {
    images
        .first()
        .map(|i| {
            Path::new(i)
                .parent()
                .unwrap_or(Path::new("."))
                .display()
                .to_string()
        })
        .unwrap_or_default()
}

/// One scene rendered and tested: its verdict and its report case.
fn test(
    a: &RegressArgs,
    gpu: &Gpu,
    job: &Job,
    reference: &Reference,
    several: bool,
) -> Result<(Verdict, Case)> {
    let wall = std::time::Instant::now();
    let scene = &job.loaded.scene;
    let o = options(
        scene,
        reference.tol.width,
        reference.tol.height,
        a.seed,
        a.direct_only,
    );
    let actual = render(gpu, scene, &o, &mut ())?.image;
    let failing = reference.failing_fraction(&actual);
    let passed = failing <= reference.tol.tolerance && !actual.has_non_finite();
    let flip = flip_map(&actual, &reference.mean)?;
    let mut provenance = super::with_driver(job.loaded.provenance.clone(), gpu);
    (
        provenance.method,
        provenance.seed,
        provenance.width,
        provenance.height,
    ) = ("paper".into(), a.seed, o.width, o.height);
    let z = reference.z_map(&actual);
    let mut verdict = Verdict {
        scene: scene.name.clone(),
        reference: a.reference.join(&job.name).display().to_string(),
        passed,
        failing_fraction: failing,
        tolerance: reference.tol.tolerance,
        flip: flip.mean,
        flip_percentiles: FLIP_PERCENTILES
            .iter()
            .map(|&p| (format!("p{p}"), flip.percentile(p)))
            .collect(),
        seed: a.seed,
        seconds: 0.0,
        provenance,
        images: Vec::new(),
    };
    if !passed {
        let dir = match (&a.out, several) {
            (Some(d), false) => d.clone(),
            (Some(d), true) => d.join(&job.name),
            (None, _) => super::out_dir("regress").join(&job.name),
        };
        std::fs::create_dir_all(&dir)?;
        verdict.images = write_failure(&dir, &actual, reference, &z)?;
    }
    verdict.seconds = wall.elapsed().as_secs_f64();
    let case = case(job, &verdict, &actual, reference, &flip, &z)?;
    Ok((verdict, case))
}

/// |z| / 4 against 1 in false colour: black below the limit's 1%, red at and past it.
fn z_picture(z: &Image) -> Image {
    false_colour(z, &Image::new(z.width, z.height))
}

/// The scene's case in the JUnit and HTML reports.
fn case(
    job: &Job,
    v: &Verdict,
    actual: &Image,
    r: &Reference,
    flip: &photonmap::metrics::FlipMap,
    z: &Image,
) -> Result<Case> {
    let failure = (!v.passed).then(|| {
        format!(
            "{:.4}% of channels beyond |z| = 4, tolerance {:.4}%; images: {}",
            100.0 * v.failing_fraction,
            100.0 * v.tolerance,
            v.images.join(", ")
        )
    });
    let mut figures = vec![
        ("scene".to_string(), job.args.scene.display().to_string()),
        ("reference".into(), v.reference.clone()),
        (
            "channels beyond |z| = 4".into(),
            format!("{:.4}%", 100.0 * v.failing_fraction),
        ),
        ("tolerance".into(), format!("{:.4}%", 100.0 * v.tolerance)),
        ("FLIP mean".into(), format!("{:.6}", v.flip)),
    ];
    for (k, x) in &v.flip_percentiles {
        figures.push((format!("FLIP {k}"), format!("{x:.6}")));
    }
    figures.push(("seed".into(), v.seed.to_string()));
    figures.push(("scene hash".into(), v.provenance.scene_hash.clone()));
    let picture = |caption: &str, png: Vec<u8>| Picture {
        caption: caption.into(),
        png,
    };
    Ok(Case {
        name: job.name.clone(),
        failure,
        warnings: Vec::new(),
        seconds: v.seconds,
        figures,
        pictures: vec![
            picture("render", actual.png_bytes()?),
            picture("reference (mean of the seeds)", r.mean.png_bytes()?),
            picture(
                "FLIP error map (magma: black 0 .. pale yellow 1)",
                flip.magma_png()?,
            ),
            picture("|z| / 4 (red: beyond |z| = 4)", z_picture(z).png_bytes()?),
        ],
    })
}

/// The image, the reference's mean and the |z| map (EXR and false colour).
fn write_failure(dir: &Path, actual: &Image, r: &Reference, z: &Image) -> Result<Vec<String>> {
    let files = [
        (dir.join("actual.exr"), actual.exr_bytes()?),
        (dir.join("actual.png"), actual.png_bytes()?),
        (dir.join("reference.exr"), r.mean.exr_bytes()?),
        (dir.join("reference.png"), r.mean.png_bytes()?),
        (dir.join("z.exr"), z.exr_bytes()?),
        (dir.join("z.png"), z_picture(z).png_bytes()?),
    ];
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    write_all_atomically(&refs)?;
    Ok(files.iter().map(|(p, _)| p.display().to_string()).collect())
}

fn print_line(v: &Verdict) {
    println!(
        "{} {}: {:.4}% of channels beyond |z| = 4 (tolerance {:.4}%), FLIP {:.4}, in {:.2} s",
        if v.passed { "pass" } else { "FAIL" },
        v.scene,
        100.0 * v.failing_fraction,
        100.0 * v.tolerance,
        v.flip,
        v.seconds
    );
}

/// Makes the reference: seeds 1..=N, and seed 1 again in a child process with
/// llvmpipe's SIMD width at 128 bits, for the driver's rounding.
fn update(a: &RegressArgs, gpu: &Gpu, job: &Job) -> Result<()> {
    let (scene, name) = (&job.loaded.scene, job.name.as_str());
    let (w, h) = (
        a.width.unwrap_or((scene.camera.width / 4).max(1)),
        a.height.unwrap_or((scene.camera.height / 4).max(1)),
    );
    let mut images = Vec::new();
    for seed in 1..=a.seeds {
        if !a.quiet {
            eprintln!("regress --update {name}: seed {seed} of {}", a.seeds);
        }
        images.push(
            render(
                gpu,
                scene,
                &options(scene, w, h, seed, a.direct_only),
                &mut (),
            )?
            .image,
        );
    }
    let narrow = narrow_simd_render(a, &job.args.scene, w, h)?;
    let mut command = format!(
        "photonmap regress {} --reference {} --update --seeds {} --width {w} --height {h}",
        job.args.scene.display(),
        a.reference.display(),
        a.seeds
    );
    for (k, v) in &a.set {
        command += &format!(" --set {k}={v}");
    }
    let tol = Tolerance {
        scene: scene.name.clone(),
        width: w,
        height: h,
        seeds: a.seeds,
        renderer: gpu.capabilities().gl_renderer,
        loo_fail_mean: 0.0,
        loo_fail_std: 0.0,
        driver_rmse: 0.0,
        tolerance: 0.0,
        command,
    };
    let reference = make_reference(&images, &narrow, tol)?;
    std::fs::create_dir_all(&a.reference)?;
    reference.write(&a.reference, name)?;
    if !a.quiet {
        eprintln!(
            "wrote {} (tolerance {:.4}%: seeds {:.4}% +- {:.4}%)",
            a.reference.join(name).display(),
            100.0 * reference.tol.tolerance,
            100.0 * reference.tol.loo_fail_mean,
            100.0 * reference.tol.loo_fail_std
        );
    }
    Ok(())
}

/// Seed 1 rendered by this very program in a child process with
/// LP_NATIVE_VECTOR_WIDTH=128.
fn narrow_simd_render(a: &RegressArgs, scene: &Path, w: u32, h: u32) -> Result<Image> {
    let dir = tempfile::tempdir()?;
    let exr = dir.path().join("narrow.exr");
    let mut child = std::process::Command::new(std::env::current_exe()?);
    child
        .env("LP_NATIVE_VECTOR_WIDTH", "128")
        .args([
            "render",
            "--quiet",
            "--seed",
            "1",
            "--width",
            &w.to_string(),
            "--height",
            &h.to_string(),
        ])
        .arg(scene)
        .arg("-o")
        .arg(&exr);
    for (k, v) in &a.set {
        child.arg("--set").arg(format!("{k}={v}"));
    }
    if a.direct_only {
        child.arg("--direct-only");
    }
    let status = child.status()?;
    if !status.success() {
        bail!("the render with a 128-bit SIMD width failed ({status})");
    }
    Ok(Image::read_exr(&exr)?)
}
