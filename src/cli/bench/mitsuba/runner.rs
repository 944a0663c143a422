//! Running Mitsuba for `bench mitsuba`: the scene exported as
//! `mitsuba_render.py` reads it, the check that `--python` imports Mitsuba,
//! and a render for a wall time with its images along the way.

use std::path::{Path, PathBuf};
use std::process::Command;

use anyhow::{bail, Context, Result};
use serde_json::json;

use photonmap::image::write_atomically;
use photonmap::render::Image;
use photonmap::scene::{Geometry, Light, Material, Scene};

use super::args::MitsubaBenchArgs;

/// The script, embedded; written beside the export for each run.
const SCRIPT: &str = include_str!("mitsuba_render.py");

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
pub fn export(scene: &Scene, width: u32, height: u32, max_depth: i32) -> serde_json::Value {
    let v = |p: glam::Vec3| [p.x, p.y, p.z];
    let material = |m: usize| match scene.materials[m] {
        Material::Diffuse { albedo } => json!({"type": "diffuse", "albedo": v(albedo)}),
        Material::Mirror { reflectance } => {
            json!({"type": "mirror", "reflectance": v(reflectance)})
        }
        Material::Glass { ior } => json!({"type": "glass", "ior": ior}),
        // Mitsuba masks by the product of the two G1 whatever is asked.
        Material::Conductor {
            eta,
            k,
            tint,
            alpha,
            microfacet,
        } => json!({"type": "conductor", "eta": v(eta), "k": v(k), "tint": v(tint), "alpha": alpha,
                    "distribution": if microfacet.beckmann { "beckmann" } else { "ggx" }}),
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
pub(super) fn check_mitsuba(a: &MitsubaBenchArgs) -> Result<()> {
    check_variant(&a.python, &a.variant)
}

/// Fails unless `python` imports Mitsuba and sets `variant`.
pub fn check_variant(python: &str, variant: &str) -> Result<()> {
    let check = Command::new(python)
        .args([
            "-c",
            &format!("import mitsuba; mitsuba.set_variant('{variant}')"),
        ])
        .output()
        .with_context(|| format!("running {python} (--python)"))?;
    if !check.status.success() {
        bail!(
            "{} cannot run Mitsuba's {} variant: {}\n{INSTALL}",
            python,
            variant,
            String::from_utf8_lossy(&check.stderr)
                .lines()
                .last()
                .unwrap_or("")
        );
    }
    Ok(())
}

const INSTALL: &str = "(pip install mitsuba; its LLVM back end needs libLLVM 16 or newer, named by DRJIT_LIBLLVM_PATH)";

/// A render's image at some point of its run: (wall seconds, samples, image).
pub(super) type Taken = (f64, u32, Image);

/// Renders the export with Mitsuba's `integrator` for `seconds` of wall
/// time: the final image, its seconds and samples per pixel, and the running
/// mean after the first pass past each of `checkpoints` (seconds).
pub(super) fn render_mitsuba(
    a: &MitsubaBenchArgs,
    dir: &Path,
    integrator: &str,
    seconds: f64,
    checkpoints: &[f64],
    seed: u32,
) -> Result<(Taken, Vec<Taken>)> {
    let exr = dir.join(format!("mitsuba_{integrator}.exr"));
    let marks: Vec<String> = checkpoints.iter().map(|c| format!("{c}")).collect();
    let run = Command::new(&a.python)
        .arg(dir.join(SCRIPT_FILE))
        .arg(dir.join(EXPORT_FILE))
        .arg(format!("{seconds}"))
        .arg(&exr)
        .arg(integrator)
        .arg(&a.variant)
        .arg(marks.join(","))
        .arg(format!("{seed}"))
        .output()
        .with_context(|| format!("running {}", a.python))?;
    succeeded(&run)?;
    let report = report_line(&run.stdout)?;
    let taken = |r: &serde_json::Value, file: &Path| -> Result<Taken> {
        let image = Image::read_exr(file)?;
        let _ = std::fs::remove_file(file);
        Ok((
            r["seconds"].as_f64().unwrap_or(f64::NAN),
            r["spp"].as_u64().unwrap_or(0) as u32,
            image,
        ))
    };
    let mut along = Vec::new();
    for c in report["checkpoints"].as_array().into_iter().flatten() {
        let file = PathBuf::from(c["file"].as_str().unwrap_or_default());
        along.push(taken(c, &file)?);
    }
    Ok((taken(&report, &exr)?, along))
}

/// Fails with the last lines of a script's stderr unless it succeeded.
fn succeeded(run: &std::process::Output) -> Result<()> {
    if !run.status.success() {
        let err = String::from_utf8_lossy(&run.stderr);
        let tail: Vec<&str> = err.lines().rev().take(6).collect();
        bail!(
            "Mitsuba failed ({}): {}\n{INSTALL}",
            run.status,
            tail.into_iter().rev().collect::<Vec<_>>().join("\n")
        );
    }
    Ok(())
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

/// What Mitsuba runs from, into `dir`: the scene's export at `size` and the script.
pub(super) fn write_inputs(
    dir: &Path,
    scene: &Scene,
    (width, height): (u32, u32),
    max_depth: i32,
) -> Result<()> {
    let exported = export(scene, width, height, max_depth);
    write_atomically(
        &dir.join(EXPORT_FILE),
        serde_json::to_string(&exported)?.as_bytes(),
    )?;
    write_atomically(&dir.join(SCRIPT_FILE), SCRIPT.as_bytes())?;
    Ok(())
}

/// Removes the script once the races are run: it is this binary's own
/// (src/cli/bench/mitsuba/mitsuba_render.py); the export stays, as the record
/// of what Mitsuba rendered.
pub(super) fn remove_script(dir: &Path) {
    let _ = std::fs::remove_file(dir.join(SCRIPT_FILE));
}

/// The rate script, embedded; written beside `mitsuba_render.py`, whose
/// scene it renders.
const RATES_SCRIPT: &str = include_str!("throughput.py");

/// Mitsuba 3's rates on a scene (`throughput.py`): wall seconds of its
/// `direct` integrator, and light paths per second of `ptracer`.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct MitsubaRates {
    /// The least of the timed `direct` renders, and the first (compiling) one.
    pub direct_seconds: f64,
    pub direct_first_seconds: f64,
    /// Light paths of one `ptracer` render and the least of its times.
    pub ptracer_paths: u64,
    pub ptracer_seconds: f64,
    pub ptracer_first_seconds: f64,
}

/// Runs `throughput.py` on `scene` at `size`: `direct` at `spp` with
/// `emitter_samples`, and `ptracer` at `ptracer_spp`, each `repeats` times
/// after one that compiles. `dir` holds the export, which stays.
pub fn mitsuba_rates(
    (python, variant): (&str, &str),
    dir: &Path,
    scene: &Scene,
    size: (u32, u32),
    (spp, emitter_samples, ptracer_spp, repeats): (u32, u32, u32, u32),
) -> Result<MitsubaRates> {
    write_inputs(dir, scene, size, -1)?;
    let script = dir.join("throughput.py");
    write_atomically(&script, RATES_SCRIPT.as_bytes())?;
    let run = Command::new(python)
        .arg(&script)
        .arg(dir.join(EXPORT_FILE))
        .args([spp, emitter_samples, ptracer_spp].map(|v| v.to_string()))
        .arg(variant)
        .arg(repeats.to_string())
        .output()
        .with_context(|| format!("running {python}"));
    let _ = std::fs::remove_file(&script);
    remove_script(dir);
    let run = run?;
    succeeded(&run)?;
    Ok(serde_json::from_value(report_line(&run.stdout)?)?)
}
