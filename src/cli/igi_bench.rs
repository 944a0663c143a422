//! `photonmap bench igi`: Marques and Santos's figures 4 and 5 on this
//! pipeline. Instant global illumination with its accelerations added one at
//! a time (imperfect visibility, then downsampling 4 x 4, then interleaving
//! 3 x 3), and the remedies they suggest for the combination's artefacts;
//! each row's time split by component (direct light, specular paths,
//! indirect diffuse by VPLs, caustics by the caustic photon map), and its
//! error against the scene's SPPM reference when there is one.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;
use serde::Serialize;

use photonmap::gpu::Platform;
use photonmap::image::write_atomically;
use photonmap::metrics::compare;
use photonmap::render::{render, IgiOptions, Image, Method, RenderOptions, WithCausticMap};
use photonmap::scene::{embedded, Scene};

use super::accuracy::default_reference;
use super::args::in_range;
use super::reference::{read_reference, reference_options};

/// The scene a method benchmark renders, and its reference.
#[derive(Args)]
pub struct BenchScene {
    /// Scene file or embedded name.
    #[arg(long, required_unless_present = "triangles")]
    pub scene: Option<PathBuf>,
    /// Render `bench meshes`'s stage instead, its ball a mesh of about this
    /// many triangles (1024..=4194304).
    #[arg(long, value_name = "N", value_parser = in_range(1024, 1 << 22), conflicts_with = "scene")]
    pub triangles: Option<u32>,
    /// SPPM reference EXR (default: the scene's, as `bench accuracy` finds it;
    /// none for the mesh stage). Images render at its size.
    #[arg(long)]
    pub reference: Option<PathBuf>,
}

#[derive(Args)]
pub struct IgiBenchArgs {
    #[command(flatten)]
    pub scene: BenchScene,
    /// Light paths for VPLs (1..=1048576).
    #[arg(long, default_value_t = 64, value_parser = in_range(1, 1 << 20))]
    pub vpl_paths: u32,
    /// Folder for each row's PNG (default photonmap-out/igi/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
    #[arg(long)]
    pub quiet: bool,
}

/// One configuration's render.
#[derive(Serialize, Clone, Debug)]
pub struct IgiRow {
    pub label: String,
    pub options: IgiOptions,
    pub vpls: u32,
    pub seconds: f64,
    /// Wall seconds by component: direct light (eye rays, hits, shadow
    /// rays), specular continuation, indirect diffuse (VPL paths, VPLs,
    /// gather, discontinuity buffer, upsampling), caustics (the caustic
    /// map's photons, build and estimate), and the rest.
    pub direct: f64,
    pub specular: f64,
    pub indirect: f64,
    pub caustics: f64,
    pub other: f64,
    /// Against the SPPM reference (None without one).
    pub rmse: Option<f64>,
    pub ssim: Option<f64>,
    /// Against the first row (the canonical IGI on the same VPLs): what the
    /// accelerations alone change.
    pub rmse_to_canonical: f64,
}

#[derive(Serialize)]
pub struct IgiBench {
    pub scene: String,
    pub triangles: usize,
    pub width: u32,
    pub height: u32,
    pub reference: Option<String>,
    pub renderer: String,
    pub rows: Vec<IgiRow>,
}

/// The rows: the paper's four cumulative versions, then its remedies.
fn rows(paths: u32) -> Vec<(&'static str, IgiOptions)> {
    let base = IgiOptions {
        vpl_paths: paths,
        ..IgiOptions::default()
    };
    let imperfect = IgiOptions {
        imperfect_visibility: true,
        ..base.clone()
    };
    let down = IgiOptions {
        downsample: 4,
        ..imperfect.clone()
    };
    let all = IgiOptions {
        interleave: 3,
        ..down.clone()
    };
    vec![
        ("IGI", base),
        ("+ imperfect visibility", imperfect),
        ("+ downsampling 4x4", down),
        ("+ interleaving 3x3", all.clone()),
        (
            "remedy: interleaving 2x2",
            IgiOptions {
                interleave: 2,
                ..all.clone()
            },
        ),
        (
            "remedy: downsampling 2x2",
            IgiOptions {
                downsample: 2,
                ..all
            },
        ),
    ]
}

fn component(stage: &str) -> usize {
    match stage {
        "eye rays" | "intersect" | "shadow rays" => 0,
        "specular" => 1,
        "VPL paths"
        | "VPLs"
        | "VPL gather"
        | "discontinuity buffer"
        | "upsample"
        | "VPL compose" => 2,
        "trace photons" | "build map" | "radiance estimate" => 3,
        _ => 4,
    }
}

pub fn run(a: &IgiBenchArgs, platform: Platform) -> Result<()> {
    let (scene, name, reference, scale) = scene_and_reference(&a.scene)?;
    let gpu = super::gpu(platform)?;
    let progress = super::progress_lines(a.quiet);
    let dir = a
        .out
        .clone()
        .unwrap_or_else(|| super::out_dir("igi").join(&name));
    std::fs::create_dir_all(&dir)?;
    let mut out = Vec::new();
    let mut canonical: Option<Image> = None;
    let all = rows(a.vpl_paths);
    for (i, (label, igi)) in all.iter().enumerate() {
        progress(&format!("{label} ({}/{})", i + 1, all.len()));
        let o: RenderOptions = reference_options(&scene, scale, 7);
        let map = o.method.photon_map().cloned().unwrap_or_default();
        let o = o.with_method(Method::Igi(WithCausticMap::from_map(map, igi.clone())));
        let r = render(&gpu, &scene, &o, &mut ())?;
        let mut parts = [0.0f64; 5];
        for s in &r.timings.stages {
            parts[component(&s.name)] += s.wall_seconds;
        }
        let (rmse, ssim) = match &reference {
            Some((_, img)) => {
                let m = compare(&r.image, img, None)?;
                (Some(m.rmse), Some(m.ssim))
            }
            None => (None, None),
        };
        let to_canonical = match &canonical {
            Some(c) => compare(&r.image, c, None)?.rmse,
            None => 0.0,
        };
        let file = format!("{:02}_{}.png", i, slug(label));
        write_atomically(&dir.join(file), &r.image.png_bytes()?)?;
        out.push(IgiRow {
            label: label.to_string(),
            options: igi.clone(),
            vpls: r.vpls().map_or(0, |v| v.vpls),
            seconds: r.timings.wall_seconds,
            direct: parts[0],
            specular: parts[1],
            indirect: parts[2],
            caustics: parts[3],
            other: parts[4],
            rmse,
            ssim,
            rmse_to_canonical: to_canonical,
        });
        if canonical.is_none() {
            canonical = Some(r.image);
        }
    }
    let report = IgiBench {
        scene: name,
        triangles: scene.shapes.len(),
        width: (scene.camera.width / scale).max(1),
        height: (scene.camera.height / scale).max(1),
        reference: reference.map(|(p, _)| p.display().to_string()),
        renderer: gpu.capabilities().gl_renderer,
        rows: out,
    };
    write_atomically(
        &dir.join("igi.json"),
        serde_json::to_string_pretty(&report)?.as_bytes(),
    )?;
    if a.json {
        return super::print_json(&report);
    }
    print_table(&report);
    eprintln!("wrote {}", dir.display());
    Ok(())
}

/// The scene (a file or embedded name, or `bench meshes`' stage of about
/// `triangles` triangles), its name, its SPPM reference when there is one
/// (given, or the scene's as `bench accuracy` finds it; none for the stage),
/// and the reference's scale below the scene's resolution.
#[allow(clippy::type_complexity)]
pub(super) fn scene_and_reference(
    s: &BenchScene,
) -> Result<(Scene, String, Option<(PathBuf, Image)>, u32)> {
    let (a_scene, triangles, reference) = (&s.scene, s.triangles, &s.reference);
    let (scene, name): (Scene, String) = match (triangles, a_scene) {
        (Some(n), _) => (super::meshes::stage(n)?, format!("stage_{n}")),
        (None, Some(s)) => (embedded::load_path_or_name(s)?, super::accuracy::stem(s)),
        (None, None) => bail!("give --scene or --triangles"),
    };
    let reference = match (reference, a_scene) {
        (Some(r), _) => Some(r.clone()),
        (None, Some(s)) if triangles.is_none() => {
            Some(default_reference(s)).filter(|r| r.is_file())
        }
        _ => None,
    };
    let reference = reference
        .map(|r| -> Result<(PathBuf, Image)> { Ok((r.clone(), read_reference(&r)?.0)) })
        .transpose()?;
    let scale = match &reference {
        Some((path, img)) => {
            if img.width == 0 || !scene.camera.width.is_multiple_of(img.width) {
                bail!(
                    "{}: {} x {} pixels is not the scene's {} x {} divided by a whole number",
                    path.display(),
                    img.width,
                    img.height,
                    scene.camera.width,
                    scene.camera.height
                );
            }
            scene.camera.width / img.width
        }
        None => 1,
    };
    Ok((scene, name, reference, scale))
}

fn print_table(report: &IgiBench) {
    println!(
        "{} ({} primitives, {} x {}, {})",
        report.scene, report.triangles, report.width, report.height, report.renderer
    );
    println!(
        "{:<26} {:>6} {:>8} {:>7} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9}",
        "run",
        "VPLs",
        "seconds",
        "fps",
        "direct",
        "specular",
        "indirect",
        "caustics",
        "RMSE",
        "vs IGI"
    );
    for r in &report.rows {
        println!(
            "{:<26} {:>6} {:>8.3} {:>7.3} {:>7.0}% {:>7.0}% {:>7.0}% {:>7.0}% {:>8} {:>9.5}",
            r.label,
            r.vpls,
            r.seconds,
            1.0 / r.seconds,
            100.0 * r.direct / r.seconds,
            100.0 * r.specular / r.seconds,
            100.0 * r.indirect / r.seconds,
            100.0 * r.caustics / r.seconds,
            r.rmse.map_or("-".into(), |v| format!("{v:.5}")),
            r.rmse_to_canonical
        );
    }
}

pub(super) fn slug(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect::<String>()
        .split('_')
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}
