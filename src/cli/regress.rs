//! `photonmap regress`: image regression for CI in one command. Renders the
//! scene at its reference's size, runs the per-pixel z-test against the
//! reference's mean and variance, prints a verdict, and on failure writes the
//! image, the reference and the error map. JSON and JUnit XML reports.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_all_atomically;
use photonmap::metrics::false_colour;
use photonmap::regress::{make_reference, Reference, Tolerance};
use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::Scene;

use super::args::{in_range, SceneArgs};

/// Render a scene and test it against a regression reference (the z-test of
/// tests/gpu/reference_images.rs); --update makes the reference instead.
#[derive(Args)]
pub struct RegressArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// The folder of the reference: <scene>.exr (mean), <scene>.var.exr, <scene>.json.
    #[arg(long, value_name = "DIR")]
    pub reference: PathBuf,
    /// The reference's name in the folder (default: the scene file's stem).
    #[arg(long)]
    pub name: Option<String>,
    /// The render's seed (the reference is made from seeds 1..=N; keep it out of them).
    #[arg(long, default_value_t = 1000)]
    pub seed: u32,
    /// Direct light and specular paths only (a render without its photon map).
    #[arg(long)]
    pub direct_only: bool,
    /// Where images go when the test fails (default: photonmap-out/regress/<name>/).
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Make (or remake) the reference from --seeds renders at --width x --height.
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
    /// Print the report as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Also write the report as JUnit XML to this file.
    #[arg(long, value_name = "XML")]
    pub junit: Option<PathBuf>,
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
    seed: u32,
    seconds: f64,
    provenance: photonmap::provenance::Provenance,
    images: Vec<String>,
}

fn options(scene: &Scene, width: u32, height: u32, seed: u32, direct_only: bool) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (width, height, seed);
    if direct_only {
        o = o.direct_only();
    }
    o
}

pub fn run(a: &RegressArgs, platform: Platform) -> Result<()> {
    let loaded = a.scene.load()?;
    let name = a.name.clone().unwrap_or_else(|| {
        a.scene
            .scene
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    });
    let gpu = super::gpu(platform)?;
    if a.update {
        return update(a, &gpu, &loaded.scene, &name);
    }
    let reference = Reference::load(&a.reference, &name)?;
    let wall = std::time::Instant::now();
    let o = options(
        &loaded.scene,
        reference.tol.width,
        reference.tol.height,
        a.seed,
        a.direct_only,
    );
    let actual = render(&gpu, &loaded.scene, &o, &mut ())?.image;
    let failing = reference.failing_fraction(&actual);
    let passed = failing <= reference.tol.tolerance && !actual.has_non_finite();
    let mut provenance = super::with_driver(loaded.provenance, &gpu);
    (
        provenance.method,
        provenance.seed,
        provenance.width,
        provenance.height,
    ) = ("paper".into(), a.seed, o.width, o.height);
    let mut verdict = Verdict {
        scene: loaded.scene.name.clone(),
        reference: a.reference.join(&name).display().to_string(),
        passed,
        failing_fraction: failing,
        tolerance: reference.tol.tolerance,
        seed: a.seed,
        seconds: wall.elapsed().as_secs_f64(),
        provenance,
        images: Vec::new(),
    };
    if !passed {
        let dir = a
            .out
            .clone()
            .unwrap_or_else(|| super::out_dir("regress").join(&name));
        std::fs::create_dir_all(&dir)?;
        verdict.images = write_failure(&dir, &actual, &reference)?;
    }
    report(a, &verdict)?;
    if !passed {
        bail!(
            "{}: {:.4}% of channels beyond |z| = 4, tolerance {:.4}%: images in {}",
            name,
            100.0 * failing,
            100.0 * reference.tol.tolerance,
            verdict
                .images
                .first()
                .map(|i| Path::new(i)
                    .parent()
                    .unwrap_or(Path::new("."))
                    .display()
                    .to_string())
                .unwrap_or_default()
        );
    }
    Ok(())
}

/// The image, the reference's mean and the |z| map (EXR and false colour).
fn write_failure(dir: &Path, actual: &Image, r: &Reference) -> Result<Vec<String>> {
    let z = r.z_map(actual);
    let mut one = Image::new(z.width, z.height);
    for p in &mut one.pixels {
        *p = [1.0; 3];
    }
    let files = [
        (dir.join("actual.exr"), actual.exr_bytes()?),
        (dir.join("actual.png"), actual.png_bytes()?),
        (dir.join("reference.exr"), r.mean.exr_bytes()?),
        (dir.join("reference.png"), r.mean.png_bytes()?),
        (dir.join("z.exr"), z.exr_bytes()?),
        // |z| / 4 against 1: black below the limit's 1%, red at and past it.
        (
            dir.join("z.png"),
            false_colour(&z, &Image::new(z.width, z.height)).png_bytes()?,
        ),
    ];
    let refs: Vec<(&Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    write_all_atomically(&refs)?;
    Ok(files.iter().map(|(p, _)| p.display().to_string()).collect())
}

fn report(a: &RegressArgs, v: &Verdict) -> Result<()> {
    if a.json {
        super::print_json(v)?;
    } else if !a.quiet {
        println!(
            "{} {}: {:.4}% of channels beyond |z| = 4 (tolerance {:.4}%) in {:.2} s",
            if v.passed { "pass" } else { "FAIL" },
            v.scene,
            100.0 * v.failing_fraction,
            100.0 * v.tolerance,
            v.seconds
        );
    }
    if let Some(path) = &a.junit {
        photonmap::image::write_atomically(path, junit(v).as_bytes())?;
    }
    Ok(())
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// One test suite with one test case; a failure element when it failed.
fn junit(v: &Verdict) -> String {
    let name = xml_escape(&v.scene);
    let mut s = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<testsuites>\n  <testsuite name=\"photonmap regress\" tests=\"1\" failures=\"{}\" time=\"{:.3}\">\n    <testcase classname=\"regress\" name=\"{name}\" time=\"{:.3}\">\n",
        (!v.passed) as u32,
        v.seconds,
        v.seconds
    );
    if !v.passed {
        s += &format!(
            "      <failure message=\"{:.4}% of channels beyond |z| = 4, tolerance {:.4}%\">images: {}</failure>\n",
            100.0 * v.failing_fraction,
            100.0 * v.tolerance,
            xml_escape(&v.images.join(", "))
        );
    }
    s + "    </testcase>\n  </testsuite>\n</testsuites>\n"
}

/// Makes the reference: seeds 1..=N, and seed 1 again in a child process with
/// llvmpipe's SIMD width at 128 bits, for the driver's rounding.
fn update(a: &RegressArgs, gpu: &Gpu, scene: &Scene, name: &str) -> Result<()> {
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
    let narrow = narrow_simd_render(a, w, h)?;
    let mut command = format!(
        "photonmap regress {} --reference {} --update --seeds {} --width {w} --height {h}",
        a.scene.scene.display(),
        a.reference.display(),
        a.seeds
    );
    for (k, v) in &a.scene.set {
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
fn narrow_simd_render(a: &RegressArgs, w: u32, h: u32) -> Result<Image> {
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
        .arg(&a.scene.scene)
        .arg("-o")
        .arg(&exr);
    for (k, v) in &a.scene.set {
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
