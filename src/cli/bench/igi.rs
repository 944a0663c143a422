//! `photonmap bench igi`: Marques and Santos's figures 4 and 5 on this
//! pipeline. Instant global illumination with its accelerations added one at
//! a time (imperfect visibility, then downsampling 4 x 4, then interleaving
//! 3 x 3), and the remedies they suggest for the combination's artefacts;
//! each row's time split by component (direct light, specular paths,
//! indirect diffuse by VPLs, caustics by the caustic photon map), and its
//! error against the scene's SPPM reference when there is one.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;

use photonmap::gpu::Platform;
use photonmap::metrics::compare;
use photonmap::render::{render, IgiOptions, Image, Method, RenderOptions, WithCausticMap};

use super::output::{folder, write_json, write_row_png, BenchOutput};
use super::reference::{reference_options, scaled_size};
use super::scene::{BenchScene, Loaded, SEED};
use crate::cli::args::in_range;

#[derive(Args)]
pub struct IgiBenchArgs {
    #[command(flatten)]
    pub scene: BenchScene,
    /// Light paths for VPLs (1..=1048576; the paper's 64 by default, not the render default).
    #[arg(long, default_value_t = 64, value_parser = in_range(1, 1 << 20))]
    pub vpl_paths: u32,
    /// Folder for each row's PNG (default photonmap-out/igi/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub output: BenchOutput,
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
    // The paper's versions: without the interleaving and the bias
    // compensation of the default.
    let base = IgiOptions {
        vpl_paths: paths,
        interleave: 1,
        bias_compensation: 0,
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
        // The fused eye path holds the specular chain too.
        "eye rays" | "intersect" | "shadow rays" | "eye paths (fused)" => 0,
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
    let Loaded {
        scene,
        name,
        reference,
        scale,
    } = a.scene.load()?;
    let gpu = crate::cli::gpu(platform)?;
    let progress = a.output.progress();
    let dir = folder(a.out.as_deref(), "igi", Some(&name))?;
    let mut out = Vec::new();
    let mut canonical: Option<Image> = None;
    let all = rows(a.vpl_paths);
    for (i, (label, igi)) in all.iter().enumerate() {
        progress(&format!("{label} ({}/{})", i + 1, all.len()));
        let o: RenderOptions = reference_options(&scene, scale, SEED);
        let map = o.method.photon_map().cloned().unwrap_or_default();
        let o = o.with_method(Method::Igi(WithCausticMap::from_map(map, igi.clone())));
        let r = render(&gpu, &scene, &o, &mut ())?;
        let parts: [f64; 5] = r.timings.wall_by_component(component);
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
        write_row_png(&dir, i, label, &r.image)?;
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
    let (width, height) = scaled_size(&scene, scale);
    let report = IgiBench {
        scene: name,
        triangles: scene.shapes.len(),
        width,
        height,
        reference: reference.map(|(p, _)| p.display().to_string()),
        renderer: gpu.capabilities().gl_renderer,
        rows: out,
    };
    write_json(&dir.join("igi.json"), &report)?;
    a.output.print(&report, |r| {
        print_table(r);
        eprintln!("wrote {}", dir.display());
    })
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
