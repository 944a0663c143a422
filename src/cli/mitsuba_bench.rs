//! `photonmap bench mitsuba`: photonmap's SPPM at its defaults against what
//! a user would pick instead, Mitsuba 3, on the same machine for the same
//! wall times (`--seconds`), all compared with independent ground truth
//! (reference_images/truth/: Mitsuba plus a separate light tracer, on the
//! pixels of its interior mask); relative RMSE against seconds for each
//! method as `convergence.svg`. `--spp` adds photonmap's one-map render at
//! its defaults, and gives SPPM and Mitsuba each render's wall time. The
//! scene is exported (camera, shapes as meshes, spheres and cylinders,
//! materials, lights) for `mitsuba_render.py`, which this binary embeds and
//! runs with `--python`; Mitsuba itself is not a dependency of this program
//! or its tests (`pip install mitsuba`; its LLVM back end needs libLLVM 16
//! or newer, named by DRJIT_LIBLLVM_PATH where the system's is older).

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use clap::Args;
use serde::Serialize;
use serde_json::json;

use photonmap::gpu::{Gpu, Platform};
use photonmap::image::write_atomically;
use photonmap::metrics::{compare, Metrics};
use photonmap::render::sppm::{render_sppm, SppmOptions};
use photonmap::render::{render, EstimatePass, Image, RenderObserver};
use photonmap::scene::{embedded, Geometry, Light, Material, Scene};

use super::accuracy::{default_reference, stem};
use super::args::in_range;
use super::compare::read_mask;
use super::plot::LogLog;
use super::reference::reference_options;

const SCRIPT: &str = include_str!("mitsuba_render.py");

/// The committed ground truth: <scene>.exr, <scene>_interior_mask.png and
/// noise.json (relative to the working directory, as the SPPM references).
const TRUTH: &str = "reference_images/truth";

#[derive(Args)]
pub struct MitsubaBenchArgs {
    /// Scene file or embedded name.
    #[arg(long)]
    pub scene: PathBuf,
    /// The image every render is compared with (linear EXR; default
    /// reference_images/truth/<scene>.exr where it exists, else the scene's
    /// SPPM reference as `bench accuracy` finds it). Everything renders at
    /// its size, which must be the scene's divided by a whole number.
    #[arg(long, value_name = "EXR", conflicts_with = "mitsuba_reference")]
    pub reference: Option<PathBuf>,
    /// For scenes without committed truth: the reference is Mitsuba's path
    /// tracer, two independent runs of this many seconds each, averaged
    /// (`reference.exr` in --out); their difference gives its noise. Path
    /// tracing converges to the exact image, but slowly where light reaches
    /// diffuse surfaces through mirrors or glass, and never from a point
    /// light through them: use it for scenes it handles.
    #[arg(long, value_name = "SECONDS", value_parser = budget_seconds)]
    pub mitsuba_reference: Option<f64>,
    /// With --mitsuba-reference: render at the scene's size divided by this
    /// (1..=16; the size must divide).
    #[arg(long, default_value_t = 2, value_parser = in_range(1, 16), requires = "mitsuba_reference")]
    pub scale: u32,
    /// Only pixels where this PNG (the reference's size) is bright count
    /// (default with the default truth: its interior mask,
    /// reference_images/truth/<scene>_interior_mask.png; otherwise every
    /// pixel).
    #[arg(long, value_name = "PNG")]
    pub mask: Option<PathBuf>,
    /// Wall-time budgets in seconds (e.g. 30,60,120): photonmap's SPPM at
    /// its defaults and each Mitsuba integrator render for each; the longest
    /// also records the convergence curves.
    #[arg(long, value_delimiter = ',', value_parser = budget_seconds)]
    pub seconds: Vec<f64>,
    /// photonmap's one-map render at its defaults with this many eye
    /// samples per pixel (1..=1024), one render each; SPPM and Mitsuba get
    /// each render's wall time (default 1 without --seconds, none with it).
    #[arg(long, value_delimiter = ',', value_parser = in_range(1, 1024))]
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
    /// Mitsuba's longest path (max_depth: -1, Mitsuba's default, leaves
    /// paths to Russian roulette; else 1..=1024).
    #[arg(long, default_value_t = -1, allow_negative_numbers = true, value_parser = max_depth)]
    pub max_depth: i32,
    /// Folder for the export, the script, each image, mitsuba.json and
    /// convergence.svg (default photonmap-out/mitsuba/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

/// Mitsuba's max_depth: -1 (unbounded) or 1..=1024.
fn max_depth(s: &str) -> Result<i32, String> {
    match s.trim().parse::<i32>() {
        Ok(v) if v == -1 || (1..=1024).contains(&v) => Ok(v),
        _ => Err(format!("{s}: give -1 (no limit) or a depth in 1..=1024")),
    }
}

/// A budget: a positive number of seconds, at most a day.
fn budget_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v > 0.0 && v <= 86_400.0 => Ok(v),
        _ => Err(format!("{s}: give seconds above 0 (at most 86400)")),
    }
}

#[derive(Serialize, Clone, Debug)]
pub struct Row {
    pub renderer: String,
    /// The wall time it was given: a --seconds budget, or the one-map
    /// render's time with --spp (None for that render itself).
    pub budget: Option<f64>,
    /// Wall seconds it took (Mitsuba: its first render call on, JIT
    /// included; SPPM: setup included).
    pub seconds: f64,
    /// Samples per pixel (Mitsuba, the one-map render) or iterations (SPPM).
    pub samples: u32,
    /// Camera paths a second: samples x width x height / seconds.
    pub paths_per_second: f64,
    /// SPPM: photons emitted a second.
    pub photons_per_second: Option<f64>,
    /// RMSE over the reference's mean, on the mask's pixels: the headline.
    pub rel_rmse: f64,
    /// The image's mean over the reference's, same pixels.
    pub energy: f64,
    /// Mean of (a - b)^2 / (b^2 + 0.01).
    pub rel_mse: f64,
    pub rmse: f64,
    /// PNG in the out folder (the EXR beside it has the same stem).
    pub image: String,
}

/// One image along a method's longest run.
#[derive(Serialize, Clone, Debug)]
pub struct CurvePoint {
    pub seconds: f64,
    pub samples: u32,
    pub rel_rmse: f64,
    pub energy: f64,
    pub rel_mse: f64,
    pub image: String,
}

/// Error against wall time for one method, along its longest run.
#[derive(Serialize, Clone, Debug)]
pub struct Curve {
    pub renderer: String,
    pub points: Vec<CurvePoint>,
}

#[derive(Serialize)]
pub struct MitsubaBench {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference: String,
    /// "truth" (the committed ground truth), "given" (--reference) or "SPPM
    /// reference".
    pub reference_kind: String,
    pub mask: Option<String>,
    pub pixels_compared: usize,
    /// The reference's own relative noise: the truth's noise.json figure
    /// (full-size image), or a --mitsuba-reference's from its two runs.
    /// Nothing is measured more finely.
    pub truth_noise: Option<f64>,
    pub gl_renderer: String,
    pub variant: String,
    pub max_depth: i32,
    pub budgets: Vec<f64>,
    pub rows: Vec<Row>,
    pub curves: Vec<Curve>,
    pub convergence_plot: String,
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
pub fn export(scene: &Scene, width: u32, height: u32, max_depth: i32) -> serde_json::Value {
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

/// A render's image at some point of its run: (wall seconds, samples, image).
type Taken = (f64, u32, Image);

/// Renders the export with Mitsuba's `integrator` for `seconds` of wall
/// time: the final image, its seconds and samples per pixel, and the running
/// mean after the first pass past each of `checkpoints` (seconds).
fn render_mitsuba(
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

/// What every image is compared with.
struct Target {
    path: PathBuf,
    kind: &'static str,
    image: Image,
    mask: Option<(PathBuf, Vec<bool>)>,
    /// The truth's noise.json figure, with the default truth.
    noise: Option<f64>,
}

impl Target {
    fn compare(&self, image: &Image) -> Result<Metrics> {
        let mask = self.mask.as_ref().map(|m| m.1.as_slice());
        Ok(compare(image, &self.image, mask)?)
    }
}

/// The reference and mask from the options, or the defaults; checked
/// against the scene's size before anything renders. Returns it and the
/// scale that renders at its size.
fn target(a: &MitsubaBenchArgs, scene: &Scene, name: &str) -> Result<(Target, u32)> {
    let truth = Path::new(TRUTH).join(format!("{name}.exr"));
    let (path, kind) = match &a.reference {
        Some(p) if !p.is_file() => bail!("--reference {}: no such file", p.display()),
        Some(p) => (p.clone(), "given"),
        None if truth.is_file() => (truth, "truth"),
        None => {
            let sppm = default_reference(&a.scene);
            if !sppm.is_file() {
                bail!(
                    "no reference for {name} (neither {} nor {}): give --reference",
                    truth.display(),
                    sppm.display()
                );
            }
            (sppm, "SPPM reference")
        }
    };
    let image =
        Image::read_exr(&path).with_context(|| format!("--reference {}", path.display()))?;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let scale = w.checked_div(image.width).unwrap_or(0);
    if scale == 0 || image.width * scale != w || image.height * scale != h {
        bail!(
            "--reference {}: {} x {} pixels is not the scene's {w} x {h} divided by a whole number",
            path.display(),
            image.width,
            image.height
        );
    }
    let mask = match &a.mask {
        Some(m) => Some(m.clone()),
        None if kind == "truth" => {
            Some(Path::new(TRUTH).join(format!("{name}_interior_mask.png"))).filter(|m| m.is_file())
        }
        None => None,
    };
    let mask = mask.map(|m| checked_mask(&m, &image)).transpose()?;
    let noise = (kind == "truth").then(|| truth_noise(name)).flatten();
    Ok((
        Target {
            path,
            kind,
            image,
            mask,
            noise,
        },
        scale,
    ))
}

/// The size a --mitsuba-reference renders at: the scene's over --scale.
fn mitsuba_reference_size(a: &MitsubaBenchArgs, scene: &Scene) -> Result<(u32, u32)> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    if w % a.scale != 0 || h % a.scale != 0 {
        bail!(
            "--scale {}: does not divide the scene's {w} x {h} pixels",
            a.scale
        );
    }
    Ok((w / a.scale, h / a.scale))
}

/// --mask, read and checked against a width x height image.
fn mask_of_size(
    a: &MitsubaBenchArgs,
    width: u32,
    height: u32,
) -> Result<Option<(PathBuf, Vec<bool>)>> {
    let blank = Image {
        width,
        height,
        pixels: vec![[0.0; 3]; (width * height) as usize],
    };
    a.mask.as_ref().map(|m| checked_mask(m, &blank)).transpose()
}

/// The mask at `m`, which must be `image`'s size and keep some pixel.
fn checked_mask(m: &Path, image: &Image) -> Result<(PathBuf, Vec<bool>)> {
    let keep = read_mask(m, image)?;
    if !keep.contains(&true) {
        bail!("--mask {}: keeps no pixel", m.display());
    }
    Ok((m.to_path_buf(), keep))
}

/// The reference as Mitsuba's path tracer makes it (--mitsuba-reference):
/// two runs with distinct seeds, averaged, written as `reference.exr`; its
/// relative noise is half the RMSE between the runs over the mean, on the
/// mask's pixels.
fn mitsuba_target(
    a: &MitsubaBenchArgs,
    dir: &Path,
    mask: Option<(PathBuf, Vec<bool>)>,
    progress: &dyn Fn(&str),
) -> Result<(Target, u32)> {
    let seconds = a.mitsuba_reference.expect("only with --mitsuba-reference");
    let mut halves = Vec::new();
    for half in 0..2u32 {
        progress(&format!(
            "reference: Mitsuba path, run {} of 2, {seconds:.1} s",
            half + 1
        ));
        let ((_, _, image), _) =
            render_mitsuba(a, dir, "path", seconds, &[], REFERENCE_SEEDS * (half + 1))?;
        halves.push(image);
    }
    let mut image = halves[0].clone();
    for (p, q) in image.pixels.iter_mut().zip(&halves[1].pixels) {
        for c in 0..3 {
            p[c] = 0.5 * (p[c] + q[c]);
        }
    }
    let keep = |i: usize| mask.as_ref().is_none_or(|m| m.1[i]);
    let (mut squared, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    for (i, (p, q)) in halves[0].pixels.iter().zip(&halves[1].pixels).enumerate() {
        if keep(i) {
            for c in 0..3 {
                squared += f64::from(p[c] - q[c]).powi(2);
                sum += 0.5 * f64::from(p[c] + q[c]);
            }
            n += 3;
        }
    }
    let noise = 0.5 * (squared / n as f64).sqrt() / (sum / n as f64);
    let path = dir.join("reference.exr");
    write_atomically(&path, &image.exr_bytes()?)?;
    Ok((
        Target {
            path,
            kind: "Mitsuba path reference",
            image,
            mask,
            noise: Some(noise),
        },
        a.scale,
    ))
}

/// The reference runs' first seeds: far from the benchmark's own (0..).
const REFERENCE_SEEDS: u32 = 1 << 20;

/// The truth's relative noise (full-size image) from its noise.json.
fn truth_noise(name: &str) -> Option<f64> {
    let text = std::fs::read_to_string(Path::new(TRUTH).join("noise.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v[name]["rel_rmse_estimate_full"].as_f64()
}

/// Where rows are written and what they are compared with.
struct Bench<'a> {
    dir: &'a Path,
    target: &'a Target,
    width: u32,
    height: u32,
}

impl Bench<'_> {
    /// `image` compared with the target and written as `<stem>.png`
    /// (and `<stem>.exr` when `exr`).
    fn measure(&self, image: &Image, stem: &str, exr: bool) -> Result<(Metrics, String)> {
        let m = self.target.compare(image)?;
        let file = format!("{stem}.png");
        write_atomically(&self.dir.join(&file), &image.png_bytes()?)?;
        if exr {
            write_atomically(&self.dir.join(format!("{stem}.exr")), &image.exr_bytes()?)?;
        }
        Ok((m, file))
    }

    /// A row: `image`, taken in (seconds, samples), compared and written.
    fn row(
        &self,
        renderer: &str,
        budget: Option<f64>,
        (seconds, samples, image): &Taken,
        photons: Option<u64>,
        stem: &str,
    ) -> Result<Row> {
        let (m, file) = self.measure(image, stem, true)?;
        let pixels = self.width as f64 * self.height as f64;
        Ok(Row {
            renderer: renderer.into(),
            budget,
            seconds: *seconds,
            samples: *samples,
            paths_per_second: *samples as f64 * pixels / seconds,
            photons_per_second: photons.map(|p| p as f64 / seconds),
            rel_rmse: m.rel_rmse,
            energy: m.energy,
            rel_mse: m.rel_mse,
            rmse: m.rmse,
            image: file,
        })
    }

    /// A curve: the images along a run, then its final row.
    fn curve(&self, renderer: &str, stem: &str, along: &[Taken], last: &Row) -> Result<Curve> {
        let mut points = Vec::new();
        for (i, (seconds, samples, image)) in along.iter().enumerate() {
            let (m, file) = self.measure(image, &format!("{stem}_at{i}"), false)?;
            points.push(CurvePoint {
                seconds: *seconds,
                samples: *samples,
                rel_rmse: m.rel_rmse,
                energy: m.energy,
                rel_mse: m.rel_mse,
                image: file,
            });
        }
        points.push(CurvePoint {
            seconds: last.seconds,
            samples: last.samples,
            rel_rmse: last.rel_rmse,
            energy: last.energy,
            rel_mse: last.rel_mse,
            image: last.image.clone(),
        });
        Ok(Curve {
            renderer: renderer.into(),
            points,
        })
    }
}

/// Keeps SPPM's running image after the first iteration past each mark
/// (seconds on the caller's clock, this observer's own time not counted).
struct Checkpoints {
    marks: Vec<f64>,
    start: Instant,
    own: f64,
    taken: Vec<Taken>,
}

impl Checkpoints {
    fn new(mut marks: Vec<f64>) -> Self {
        marks.sort_by(f64::total_cmp);
        Self {
            marks,
            start: Instant::now(),
            own: 0.0,
            taken: Vec::new(),
        }
    }

    fn seconds(&self) -> f64 {
        self.start.elapsed().as_secs_f64() - self.own
    }
}

impl RenderObserver for Checkpoints {
    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> photonmap::Result<()> {
        let t = self.seconds();
        if pass.finished || self.marks.first().is_none_or(|&m| t < m) {
            return Ok(());
        }
        let t0 = Instant::now();
        self.marks.retain(|&m| m > t);
        self.taken.push((t, pass.pass + 1, pass.image()?));
        self.own += t0.elapsed().as_secs_f64();
        Ok(())
    }
}

/// The longest run's checkpoints: 1/32, 1/16, .., 1/2 of its budget.
fn marks(budget: f64) -> Vec<f64> {
    (1..=5)
        .rev()
        .map(|k| budget / f64::from(1u32 << k))
        .collect()
}

/// A budget's label in file names: "30s", "2.5s", or "1spp" (--spp).
fn label(budget: f64, spp: Option<u32>) -> String {
    match spp {
        Some(n) => format!("{n}spp"),
        None => format!("{budget}s"),
    }
}

/// SPPM at its defaults and each Mitsuba integrator for `budget` seconds:
/// their rows, and their curves when `longest`.
fn race(
    a: &MitsubaBenchArgs,
    (gpu, scene, scale): (&Gpu, &Scene, u32),
    bench: &Bench,
    (budget, spp): (f64, Option<u32>),
    longest: bool,
    (rows, curves): (&mut Vec<Row>, &mut Vec<Curve>),
) -> Result<()> {
    let progress = super::progress_lines(a.quiet);
    let tag = label(budget, spp);
    let checkpoints = if longest { marks(budget) } else { Vec::new() };
    progress(&format!("photonmap SPPM, {budget:.1} s"));
    let sppm = SppmOptions {
        iterations: 1_000_000,
        seconds: Some(budget),
        ..SppmOptions::default()
    };
    let o = reference_options(scene, scale, 7);
    let mut watch = Checkpoints::new(checkpoints.clone());
    let s = render_sppm(gpu, scene, &o, &sppm, &mut watch)?;
    let taken = (watch.seconds(), s.iterations, s.image);
    let stem = format!("photonmap_sppm_{tag}");
    let row = bench.row(
        "photonmap SPPM",
        Some(budget),
        &taken,
        Some(s.photons_emitted),
        &stem,
    )?;
    if longest {
        curves.push(bench.curve("photonmap SPPM", &stem, &watch.taken, &row)?);
    }
    rows.push(row);
    for integrator in &a.integrators {
        progress(&format!("Mitsuba {integrator}, {budget:.1} s"));
        let (taken, along) = render_mitsuba(a, bench.dir, integrator, budget, &checkpoints, 0)?;
        let (label, stem) = (
            format!("Mitsuba {integrator}"),
            format!("mitsuba_{integrator}_{tag}"),
        );
        let row = bench.row(&label, Some(budget), &taken, None, &stem)?;
        if longest {
            curves.push(bench.curve(&label, &stem, &along, &row)?);
        }
        rows.push(row);
    }
    Ok(())
}

/// Everything before the races: the reference (checked, or made by
/// Mitsuba with --mitsuba-reference), the output folder, and the export and
/// script Mitsuba runs from. Returns the reference, its scale and the folder.
fn prepare(a: &MitsubaBenchArgs, scene: &Scene, name: &str) -> Result<(Target, u32, PathBuf)> {
    let given = match a.mitsuba_reference {
        None => Some(target(a, scene, name)?),
        Some(_) => None,
    };
    let (width, height) = match &given {
        Some((t, _)) => (t.image.width, t.image.height),
        None => mitsuba_reference_size(a, scene)?,
    };
    let mitsuba_mask = match given {
        Some(_) => None,
        None => mask_of_size(a, width, height)?,
    };
    check_mitsuba(a)?;
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| super::out_dir("mitsuba").join(name));
    std::fs::create_dir_all(&dir)?;
    write_atomically(
        &dir.join(EXPORT_FILE),
        serde_json::to_string(&export(scene, width, height, a.max_depth))?.as_bytes(),
    )?;
    write_atomically(&dir.join(SCRIPT_FILE), SCRIPT.as_bytes())?;
    let (target, scale) = match given {
        Some(t) => t,
        None => mitsuba_target(a, &dir, mitsuba_mask, &super::progress_lines(a.quiet))?,
    };
    Ok((target, scale, dir))
}

pub fn run(a: &MitsubaBenchArgs, platform: Platform) -> Result<()> {
    let scene = embedded::load_path_or_name(&a.scene)?;
    let name = stem(&a.scene);
    let (target, scale, dir) = prepare(a, &scene, &name)?;
    let (width, height) = (target.image.width, target.image.height);
    let progress = super::progress_lines(a.quiet);
    let gpu = super::gpu(platform)?;
    let bench = Bench {
        dir: &dir,
        target: &target,
        width,
        height,
    };
    let mut rows = Vec::new();
    // Budgets: each one-map render's time (--spp), then --seconds.
    let mut budgets: Vec<(f64, Option<u32>)> = Vec::new();
    let mut spp = a.spp.clone();
    if spp.is_empty() && a.seconds.is_empty() {
        spp.push(1);
    }
    spp.sort_unstable();
    spp.dedup();
    for &n in &spp {
        progress(&format!("photonmap, {n} spp"));
        let mut o = reference_options(&scene, scale, 7);
        o.spp = n;
        let t = Instant::now();
        let out = render(&gpu, &scene, &o, &mut ())?;
        let taken = (t.elapsed().as_secs_f64(), n, out.image);
        rows.push(bench.row(
            "photonmap",
            None,
            &taken,
            None,
            &format!("photonmap_{n}spp"),
        )?);
        budgets.push((taken.0, Some(n)));
    }
    let mut seconds = a.seconds.clone();
    seconds.sort_by(f64::total_cmp);
    seconds.dedup();
    budgets.extend(seconds.iter().map(|&s| (s, None)));
    let longest = (0..budgets.len()).max_by(|&i, &j| budgets[i].0.total_cmp(&budgets[j].0));
    let mut curves = Vec::new();
    for (i, &budget) in budgets.iter().enumerate() {
        let at = (&gpu, &scene, scale);
        race(
            a,
            at,
            &bench,
            budget,
            Some(i) == longest,
            (&mut rows, &mut curves),
        )?;
    }
    write_atomically(
        &dir.join(PLOT_FILE),
        plot(&name, &target, &rows, &curves).as_bytes(),
    )?;
    let report = MitsubaBench {
        scene: name,
        width,
        height,
        reference: target.path.display().to_string(),
        reference_kind: target.kind.into(),
        mask: target.mask.as_ref().map(|m| m.0.display().to_string()),
        pixels_compared: target.mask.as_ref().map_or((width * height) as usize, |m| {
            m.1.iter().filter(|&&k| k).count()
        }),
        truth_noise: target.noise,
        gl_renderer: gpu.capabilities().gl_renderer,
        variant: a.variant.clone(),
        max_depth: a.max_depth,
        budgets: budgets.iter().map(|b| b.0).collect(),
        rows,
        curves,
        convergence_plot: PLOT_FILE.into(),
    };
    write_atomically(
        &dir.join("mitsuba.json"),
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )?;
    write_atomically(
        &dir.join(TABLE_FILE),
        markdown_table(&report, &command_line()).as_bytes(),
    )?;
    // The script is this binary's own (src/cli/mitsuba_render.py); the
    // export stays, as the record of what Mitsuba rendered.
    let _ = std::fs::remove_file(dir.join(SCRIPT_FILE));
    if a.json {
        super::print_json(&report)
    } else {
        print_table(&report);
        println!("wrote {}", dir.display());
        Ok(())
    }
}

const PLOT_FILE: &str = "convergence.svg";
const TABLE_FILE: &str = "table.md";

/// This run's command line, for the table's heading (arguments as given).
fn command_line() -> String {
    let args: Vec<String> = std::env::args().skip(1).collect();
    format!("photonmap {}", args.join(" "))
}

/// The rows as a Markdown table, headed by the command that made them, for
/// the documentation to link rather than retype.
fn markdown_table(b: &MitsubaBench, command: &str) -> String {
    let mut s = format!("`{command}`\n\n{}; {}.\n\n", heading(b), b.gl_renderer);
    s += "| renderer | budget (s) | seconds | samples | camera paths/s | photons/s | relative RMSE | energy |\n";
    s += "|---|---|---|---|---|---|---|---|\n";
    for r in &b.rows {
        s += &format!(
            "| {} | {} | {:.1} | {} | {:.3e} | {} | {:.4} | {:.4} |\n",
            r.renderer,
            r.budget.map_or("-".into(), |x| format!("{x:.0}")),
            r.seconds,
            r.samples,
            r.paths_per_second,
            r.photons_per_second
                .map_or("-".into(), |p| format!("{p:.3e}")),
            r.rel_rmse,
            r.energy
        );
    }
    s
}

const COLOURS: [&str; 6] = [
    "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#8c564b", "#9467bd",
];

/// Relative RMSE against seconds: each method's longest run joined, its
/// shorter budgets as dots, the one-map renders as labelled dots, and the
/// truth's own noise as a level.
fn plot(name: &str, target: &Target, rows: &[Row], curves: &[Curve]) -> String {
    let mask = if target.mask.is_some() {
        "interior mask"
    } else {
        "all pixels"
    };
    let mut p = LogLog::new(
        &format!("{name}: error against wall time ({}, {mask})", target.kind),
        "wall seconds",
        "relative RMSE (RMSE / mean of the reference)",
    );
    for (c, colour) in curves.iter().zip(COLOURS.iter().cycle()) {
        p.line(
            &c.renderer,
            colour,
            c.points.iter().map(|q| (q.seconds, q.rel_rmse)).collect(),
        );
        let on_curve = |r: &Row| c.points.iter().any(|q| q.image == r.image);
        let others: Vec<_> = rows
            .iter()
            .filter(|r| r.renderer == c.renderer && !on_curve(r))
            .map(|r| (r.seconds, r.rel_rmse, String::new()))
            .collect();
        p.points(colour, others, false);
    }
    let one_map: Vec<_> = rows
        .iter()
        .filter(|r| r.budget.is_none())
        .map(|r| {
            (
                r.seconds,
                r.rel_rmse,
                format!("photonmap {} spp", r.samples),
            )
        })
        .collect();
    if !one_map.is_empty() {
        p.points("#9467bd", one_map, false);
    }
    if let Some(n) = target.noise {
        p.level("the reference's own noise", "#7f7f7f", n);
    }
    p.svg()
}

/// What was compared with what: the tables' first line.
fn heading(b: &MitsubaBench) -> String {
    format!(
        "{} ({} x {}), against {} ({}), {}, {} pixels{}",
        b.scene,
        b.width,
        b.height,
        b.reference,
        b.reference_kind,
        b.mask
            .as_deref()
            .map_or("no mask".into(), |m| format!("mask {m}")),
        b.pixels_compared,
        b.truth_noise.map_or(String::new(), |n| format!(
            ", whose own noise is {:.2}%",
            100.0 * n
        ))
    )
}

fn print_table(b: &MitsubaBench) {
    println!("{}", heading(b));
    println!(
        "{:<16} {:>7} {:>8} {:>8} {:>9} {:>9} {:>9} {:>7} {:>8}  image",
        "renderer",
        "budget",
        "seconds",
        "samples",
        "paths/s",
        "photons/s",
        "rel.RMSE",
        "energy",
        "rel.MSE"
    );
    for r in &b.rows {
        println!(
            "{:<16} {:>7} {:>8.2} {:>8} {:>9.3e} {:>9} {:>9.4} {:>7.4} {:>8.4}  {}",
            r.renderer,
            r.budget.map_or("-".into(), |s| format!("{s:.1}")),
            r.seconds,
            r.samples,
            r.paths_per_second,
            r.photons_per_second
                .map_or("-".into(), |p| format!("{p:.3e}")),
            r.rel_rmse,
            r.energy,
            r.rel_mse,
            r.image
        );
    }
    for c in &b.curves {
        let points: Vec<String> = c
            .points
            .iter()
            .map(|q| format!("{:.1} s {:.4}", q.seconds, q.rel_rmse))
            .collect();
        println!("curve {:<16} {}", c.renderer, points.join(", "));
    }
}
