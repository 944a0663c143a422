//! `photonmap bench mitsuba`: photonmap at a scene's defaults, and its SPPM
//! stopped at the same wall time, against what a user would pick instead,
//! Mitsuba 3, on the same machine at the same wall time, all compared with
//! the scene's SPPM reference (two independent runs at many more iterations). The scene is exported (camera, shapes as meshes, spheres and
//! cylinders, materials, lights) for `mitsuba_render.py`, which this binary
//! embeds and runs with `--python`; Mitsuba itself is not a dependency of
//! this program or its tests (`pip install mitsuba`; its LLVM back end needs
//! libLLVM 16 or newer, named by DRJIT_LIBLLVM_PATH where the system's is
//! older).

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use serde_json::json;

use photonmap::gpu::Platform;
use photonmap::image::write_atomically;
use photonmap::metrics::compare;
use photonmap::render::sppm::{render_sppm, SppmOptions};
use photonmap::render::{render, Image};
use photonmap::scene::{Geometry, Light, Material, Scene};

use super::args::in_range;
use super::reference::reference_options;

const SCRIPT: &str = include_str!("mitsuba_render.py");

#[derive(Args)]
pub struct MitsubaBenchArgs {
    #[command(flatten)]
    pub scene: super::igi_bench::BenchScene,
    /// photonmap's eye samples per pixel, one render each (1..=1024); Mitsuba
    /// gets each render's wall time.
    #[arg(long, value_delimiter = ',', default_values_t = [1u32], value_parser = in_range(1, 1024))]
    pub spp: Vec<u32>,
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
    /// Mitsuba's longest path (max_depth, 1..=64).
    #[arg(long, default_value_t = 16, value_parser = in_range(1, 64))]
    pub max_depth: u32,
    /// Folder for the export, the script and each image (default
    /// photonmap-out/mitsuba/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

#[derive(Serialize, Clone, Debug)]
pub struct Row {
    pub renderer: String,
    pub seconds: f64,
    /// Samples per pixel (SPPM: iterations).
    pub spp: u32,
    pub rmse: f64,
    pub rel_mse: f64,
    /// sqrt(relative MSE).
    pub rel_rmse: f64,
    pub image: String,
}

#[derive(Serialize)]
pub struct MitsubaBench {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference: String,
    pub gl_renderer: String,
    pub variant: String,
    pub max_depth: u32,
    pub rows: Vec<Row>,
}

/// A material's triangles: (material, vertices, faces).
type MeshOf = (usize, Vec<[f32; 3]>, Vec<[u32; 3]>);

/// The scene's shapes as the script reads them: planar shapes become one
/// triangle mesh per material (an emitter's triangles wound so that their
/// front faces its emitting side); spheres and cylinders stay analytic.
fn shapes(
    scene: &Scene,
    material: &dyn Fn(usize) -> serde_json::Value,
) -> (Vec<MeshOf>, Vec<serde_json::Value>, Vec<serde_json::Value>) {
    let v = |p: glam::Vec3| [p.x, p.y, p.z];
    let mut meshes: Vec<MeshOf> = Vec::new();
    let (mut spheres, mut cylinders) = (Vec::new(), Vec::new());
    for shape in &scene.shapes {
        let triangles = match shape.geometry {
            Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            } => vec![
                [corner, corner + edge1, corner + edge1 + edge2],
                [corner, corner + edge1 + edge2, corner + edge2],
            ],
            Geometry::Triangle { v0, v1, v2 } => vec![[v0, v1, v2]],
            Geometry::Sphere { center, radius } => {
                spheres.push(json!({"center": v(center), "radius": radius, "material": material(shape.material)}));
                continue;
            }
            Geometry::Cylinder {
                base,
                axis,
                radius,
                height,
            } => {
                cylinders.push(json!({"p0": v(base), "p1": v(base + height * axis), "radius": radius, "material": material(shape.material)}));
                continue;
            }
        };
        let facing = match scene.materials[shape.material] {
            Material::Emitter {
                normal: Some(n), ..
            } => Some(n),
            _ => None,
        };
        let at = match meshes.iter().position(|m| m.0 == shape.material) {
            Some(i) => i,
            None => {
                meshes.push((shape.material, Vec::new(), Vec::new()));
                meshes.len() - 1
            }
        };
        let mesh = &mut meshes[at];
        for [a, mut b, mut c] in triangles {
            if facing.is_some_and(|n| (b - a).cross(c - a).dot(n) < 0.0) {
                std::mem::swap(&mut b, &mut c);
            }
            let first = mesh.1.len() as u32;
            mesh.1.extend([v(a), v(b), v(c)]);
            mesh.2.push([first, first + 1, first + 2]);
        }
    }
    (meshes, spheres, cylinders)
}

/// The scene as `mitsuba_render.py` reads it, at `width` x `height`.
pub fn export(scene: &Scene, width: u32, height: u32, max_depth: u32) -> serde_json::Value {
    let v = |p: glam::Vec3| [p.x, p.y, p.z];
    let material = |m: usize| match scene.materials[m] {
        Material::Diffuse { albedo } => json!({"type": "diffuse", "albedo": v(albedo)}),
        Material::Mirror { reflectance } => {
            json!({"type": "mirror", "reflectance": v(reflectance)})
        }
        Material::Glass { ior } => json!({"type": "glass", "ior": ior}),
        Material::Emitter { radiance, .. } => json!({"type": "emitter", "radiance": v(radiance)}),
    };
    let (meshes, spheres, cylinders) = shapes(scene, &material);
    let points: Vec<_> = scene
        .lights
        .iter()
        .filter_map(|l| match *l {
            Light::Point {
                position,
                intensity,
            } => Some(json!({"position": v(position), "intensity": v(intensity)})),
            _ => None,
        })
        .collect();
    let c = &scene.camera;
    json!({
        "camera": {"position": v(c.position), "look_at": v(c.look_at), "up": v(c.up),
                   "vfov": c.vfov_degrees, "width": width, "height": height},
        "max_depth": max_depth,
        "batch": 4,
        "meshes": meshes.iter().map(|(m, vs, fs)| json!({"vertices": vs, "faces": fs, "material": material(*m)})).collect::<Vec<_>>(),
        "spheres": spheres,
        "cylinders": cylinders,
        "points": points,
    })
}

/// Fails, before any render, unless `--python` imports Mitsuba with the
/// variant asked for.
fn check_mitsuba(a: &MitsubaBenchArgs) -> Result<()> {
    let check = Command::new(&a.python)
        .args([
            "-c",
            &format!("import mitsuba; mitsuba.set_variant('{}')", a.variant),
        ])
        .output()
        .with_context(|| format!("running {} (--python)", a.python))?;
    if !check.status.success() {
        bail!(
            "{} cannot run Mitsuba's {} variant: {}\n{INSTALL}",
            a.python,
            a.variant,
            String::from_utf8_lossy(&check.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
    }
    Ok(())
}

const INSTALL: &str = "(pip install mitsuba; its LLVM back end needs libLLVM 16 or newer, named by DRJIT_LIBLLVM_PATH)";

/// Renders the export with Mitsuba's `integrator` for `seconds` of wall
/// time: its image and (seconds taken, samples per pixel).
fn render_mitsuba(
    a: &MitsubaBenchArgs,
    dir: &Path,
    integrator: &str,
    seconds: f64,
) -> Result<(Image, f64, u32)> {
    let exr = dir.join(format!("mitsuba_{integrator}.exr"));
    let run = Command::new(&a.python)
        .arg(dir.join(SCRIPT_FILE))
        .arg(dir.join(EXPORT_FILE))
        .arg(format!("{seconds}"))
        .arg(&exr)
        .arg(integrator)
        .arg(&a.variant)
        .output()
        .with_context(|| format!("running {}", a.python))?;
    if !run.status.success() {
        let err = String::from_utf8_lossy(&run.stderr);
        let tail: Vec<&str> = err.lines().rev().take(6).collect();
        bail!(
            "Mitsuba failed ({}): {}\n{INSTALL}",
            run.status,
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        );
    }
    let report = report_line(&run.stdout)?;
    let image = Image::read_exr(&exr)?;
    let _ = std::fs::remove_file(&exr);
    Ok((
        image,
        report["seconds"].as_f64().unwrap_or(f64::NAN),
        report["spp"].as_u64().unwrap_or(0) as u32,
    ))
}

/// The script's report: its last line of stdout that is a JSON object.
fn report_line(stdout: &[u8]) -> Result<serde_json::Value> {
    let line = stdout
        .split(|&b| b == b'\n')
        .rfind(|l| l.first() == Some(&b'{'))
        .unwrap_or_default();
    serde_json::from_slice(line).context("Mitsuba's report line")
}

const EXPORT_FILE: &str = "export.json";
const SCRIPT_FILE: &str = "mitsuba_render.py";

/// A row: `image` compared with the reference and written as `file`.
fn row(
    (dir, reference): (&Path, &Image),
    renderer: String,
    (seconds, spp): (f64, u32),
    image: &Image,
    file: String,
) -> Result<Row> {
    let m = compare(image, reference, None)?;
    write_atomically(&dir.join(&file), &image.png_bytes()?)?;
    Ok(Row {
        renderer,
        seconds,
        spp,
        rmse: m.rmse,
        rel_mse: m.rel_mse,
        rel_rmse: m.rel_mse.sqrt(),
        image: file,
    })
}

pub fn run(a: &MitsubaBenchArgs, platform: Platform) -> Result<()> {
    let (scene, name, reference, scale) = super::igi_bench::scene_and_reference(&a.scene)?;
    let Some((reference_path, reference)) = reference else {
        bail!("bench mitsuba compares against an SPPM reference: give --reference (`photonmap reference` makes one)");
    };
    check_mitsuba(a)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| super::out_dir("mitsuba").join(&name));
    std::fs::create_dir_all(&dir)?;
    let progress = super::progress_lines(a.quiet);
    let (width, height) = (reference.width, reference.height);
    write_atomically(
        &dir.join(EXPORT_FILE),
        serde_json::to_string(&export(&scene, width, height, a.max_depth))?.as_bytes(),
    )?;
    write_atomically(&dir.join(SCRIPT_FILE), SCRIPT.as_bytes())?;
    let gpu = super::gpu(platform)?;
    let at = (dir.as_path(), &reference);
    let mut rows = Vec::new();
    for &spp in &a.spp {
        progress(&format!("photonmap, {spp} spp"));
        let mut o = reference_options(&scene, scale, 7);
        o.spp = spp;
        let t = std::time::Instant::now();
        let out = render(&gpu, &scene, &o, &mut ())?;
        let seconds = t.elapsed().as_secs_f64();
        let file = format!("photonmap_{spp}spp.png");
        rows.push(row(
            at,
            "photonmap".into(),
            (seconds, spp),
            &out.image,
            file,
        )?);
        // photonmap's own converging method, SPPM, stopped at the same time.
        progress(&format!("photonmap SPPM, {seconds:.1} s"));
        let sppm = SppmOptions {
            iterations: 1_000_000,
            seconds: Some(seconds),
            ..SppmOptions::default()
        };
        let t = std::time::Instant::now();
        let o = reference_options(&scene, scale, 7);
        let s = render_sppm(&gpu, &scene, &o, &sppm, &mut ())?;
        let taken = (t.elapsed().as_secs_f64(), s.iterations);
        let file = format!("photonmap_sppm_{spp}.png");
        rows.push(row(at, "photonmap SPPM".into(), taken, &s.image, file)?);
        for integrator in &a.integrators {
            progress(&format!("Mitsuba {integrator}, {seconds:.1} s"));
            let (image, taken, samples) = render_mitsuba(a, &dir, integrator, seconds)?;
            let file = format!("mitsuba_{integrator}_{spp}.png");
            let label = format!("Mitsuba {integrator}");
            rows.push(row(at, label, (taken, samples), &image, file)?);
        }
    }
    let bench = MitsubaBench {
        scene: name,
        width,
        height,
        reference: reference_path.display().to_string(),
        gl_renderer: gpu.capabilities().gl_renderer,
        variant: a.variant.clone(),
        max_depth: a.max_depth,
        rows,
    };
    write_atomically(
        &dir.join("mitsuba.json"),
        serde_json::to_string_pretty(&bench)?.as_bytes(),
    )?;
    if a.json {
        super::print_json(&bench)
    } else {
        print_table(&bench);
        Ok(())
    }
}

fn print_table(bench: &MitsubaBench) {
    println!(
        "{} ({} x {}) against {}",
        bench.scene, bench.width, bench.height, bench.reference
    );
    println!(
        "{:<18} {:>8} {:>6} {:>8} {:>10}",
        "renderer", "seconds", "spp/it", "RMSE", "rel. RMSE"
    );
    for r in &bench.rows {
        println!(
            "{:<18} {:>8.2} {:>6} {:>8.4} {:>10.4}",
            r.renderer, r.seconds, r.spp, r.rmse, r.rel_rmse
        );
    }
}
