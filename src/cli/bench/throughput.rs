//! `photonmap bench throughput`: each stage's rate on this substrate, its
//! floor (a copy pass over as many texels as the stage has records) and
//! Mitsuba 3's rate on the same cores, in one run.
//!
//! Per scene: SPPM's iteration at its defaults by stage (eye paths, photon
//! paths, photons built and gather queries per second); a direct-light
//! render (a camera ray and `--shadow-rays` shadow rays per area light, at
//! `--spp`) against Mitsuba's `direct` integrator at the same spp, size and
//! emitter samples; and photon paths per second against `ptracer`'s light
//! paths per second.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;

use photonmap::bench::throughput::{copy_pass_seconds, render_seconds, sppm_stage_seconds};
use photonmap::gpu::{Gpu, Platform};
use photonmap::render::sppm::SppmOptions;
use photonmap::render::RenderOptions;
use photonmap::scene::{embedded, Material, Scene};

use super::mitsuba::{check_variant, mitsuba_rates, MitsubaRates};
use super::output::{command_line, folder, stem, write_json, BenchOutput};
use crate::cli::args::in_range;

#[derive(Args)]
pub struct ThroughputArgs {
    /// A scene file or embedded name (repeatable; default: variants/mesh_stage,
    /// a diffuse scene, and the three paper scenes).
    #[arg(long)]
    pub scene: Vec<PathBuf>,
    /// Image width of every measurement (16..=4096).
    #[arg(long, default_value_t = 256, value_parser = in_range(16, 4096))]
    pub width: u32,
    /// Image height (16..=4096).
    #[arg(long, default_value_t = 192, value_parser = in_range(16, 4096))]
    pub height: u32,
    /// Eye samples per pixel of the direct-light render and of Mitsuba's
    /// `direct` (1..=1024).
    #[arg(long, default_value_t = 16, value_parser = in_range(1, 1024))]
    pub spp: u32,
    /// Shadow rays per area light of the direct-light render, and Mitsuba's
    /// emitter samples (1..=1024).
    #[arg(long, default_value_t = 16, value_parser = in_range(1, 1024))]
    pub shadow_rays: u32,
    /// SPPM stage times: runs of SHORT and LONG iterations differenced
    /// (SHORT 1..=1000, LONG SHORT+1..=10000).
    #[arg(long, num_args = 2, value_names = ["SHORT", "LONG"], default_values_t = [8, 40])]
    pub iterations: Vec<u32>,
    /// Each time is the least of this many runs (1..=20).
    #[arg(long, default_value_t = 3, value_parser = in_range(1, 20))]
    pub repeats: u32,
    /// Samples per pixel of Mitsuba's `ptracer` (light paths = this x pixels; 1..=1024).
    #[arg(long, default_value_t = 16, value_parser = in_range(1, 1024))]
    pub ptracer_spp: u32,
    /// Python that imports Mitsuba 3.
    #[arg(long, default_value = "python3")]
    pub python: String,
    /// Mitsuba's variant.
    #[arg(long, default_value = "llvm_ad_rgb")]
    pub variant: String,
    /// Leave Mitsuba out: photonmap's rates and floors only.
    #[arg(long)]
    pub no_mitsuba: bool,
    /// Folder for throughput.json and Mitsuba's scene exports (default:
    /// photonmap-out/throughput/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// One stage of an SPPM iteration.
#[derive(Serialize)]
pub struct StageRow {
    pub stage: String,
    /// Records an iteration: pixels (eye paths, gather queries) or photons emitted.
    pub records: u64,
    pub unit: &'static str,
    pub seconds: f64,
    pub per_second: f64,
    /// One copy pass over `records` 16-byte texels, and the stage in such passes.
    pub copy_seconds: f64,
    pub copy_passes: f64,
}

/// The direct-light render and its Mitsuba match.
#[derive(Serialize)]
pub struct DirectRow {
    pub spp: u32,
    pub shadow_rays: u32,
    pub seconds: f64,
    pub eye_paths_per_second: f64,
    pub copy_passes: f64,
    /// Mitsuba `direct`'s least time, and photonmap's time over it.
    pub mitsuba_seconds: Option<f64>,
    pub ratio: Option<f64>,
}

#[derive(Serialize)]
pub struct SceneThroughput {
    pub scene: String,
    /// Whether every material is diffuse or emitting: only then does
    /// Mitsuba's `direct` (no specular paths) do the direct render's work.
    pub diffuse: bool,
    pub stages: Vec<StageRow>,
    pub direct: DirectRow,
    /// SPPM's photon paths per second, Mitsuba ptracer's light paths per
    /// second, and the first over the second.
    pub photon_paths_per_second: f64,
    pub ptracer_paths_per_second: Option<f64>,
    pub photon_ratio: Option<f64>,
    pub mitsuba: Option<MitsubaRates>,
}

#[derive(Serialize)]
pub struct ThroughputReport {
    pub provenance: photonmap::provenance::Provenance,
    pub command: String,
    pub width: u32,
    pub height: u32,
    pub sppm_photons_per_iteration: u32,
    pub iterations: [u32; 2],
    pub scenes: Vec<SceneThroughput>,
}

const DEFAULT_SCENES: [&str; 4] = ["variants/mesh_stage", "glass_ball", "cornell_box", "ring"];

pub fn run(a: &ThroughputArgs, platform: Platform) -> Result<()> {
    let (short, long) = (a.iterations[0], a.iterations[1]);
    if !(1..=1000).contains(&short) || long <= short || long > 10_000 {
        anyhow::bail!(
            "--iterations {short} {long}: the allowed range is 1 <= SHORT <= 1000, SHORT < LONG <= 10000"
        );
    }
    let scenes: Vec<PathBuf> = if a.scene.is_empty() {
        DEFAULT_SCENES.iter().map(PathBuf::from).collect()
    } else {
        a.scene.clone()
    };
    let loaded: Vec<(String, Scene)> = scenes
        .iter()
        .map(|p| Ok((p.display().to_string(), embedded::load_path_or_name(p)?)))
        .collect::<Result<_>>()?;
    if !a.no_mitsuba {
        check_variant(&a.python, &a.variant)?;
    }
    let out = folder(a.out.as_deref(), "throughput", None)?;
    let gpu = crate::cli::gpu(platform)?;
    let progress = a.output.progress();
    let sppm = SppmOptions::default();
    let mut rows = Vec::new();
    for (name, scene) in &loaded {
        progress(&format!(
            "{name}: SPPM stages ({short} and {long} iterations)"
        ));
        let mut row = measure(&gpu, (name, scene), a, &sppm, (short, long))?;
        if !a.no_mitsuba {
            progress(&format!("{name}: Mitsuba direct and ptracer"));
            let dir = out.join(stem(std::path::Path::new(name)));
            std::fs::create_dir_all(&dir)?;
            let m = mitsuba_rates(
                (&a.python, &a.variant),
                &dir,
                scene,
                (a.width, a.height),
                (a.spp, a.shadow_rays, a.ptracer_spp, a.repeats),
            )?;
            row.direct.mitsuba_seconds = Some(m.direct_seconds);
            row.direct.ratio = Some(row.direct.seconds / m.direct_seconds);
            let pt = m.ptracer_paths as f64 / m.ptracer_seconds;
            row.ptracer_paths_per_second = Some(pt);
            row.photon_ratio = Some(row.photon_paths_per_second / pt);
            row.mitsuba = Some(m);
        }
        rows.push(row);
    }
    let mut provenance = photonmap::provenance::Provenance::program();
    provenance.scene = scenes
        .iter()
        .map(|p| p.display().to_string())
        .collect::<Vec<_>>()
        .join(",");
    (provenance.width, provenance.height) = (a.width, a.height);
    let report = ThroughputReport {
        provenance: crate::cli::with_driver(provenance, &gpu),
        command: command_line(),
        width: a.width,
        height: a.height,
        sppm_photons_per_iteration: sppm.photons_per_iteration,
        iterations: [short, long],
        scenes: rows,
    };
    write_json(&out.join("throughput.json"), &report)?;
    a.output.print(&report, print_report)?;
    if !a.output.json {
        eprintln!("wrote {}", out.join("throughput.json").display());
    }
    Ok(())
}

/// photonmap's side for one scene.
fn measure(
    gpu: &Gpu,
    (name, scene): (&str, &Scene),
    a: &ThroughputArgs,
    sppm: &SppmOptions,
    iterations: (u32, u32),
) -> Result<SceneThroughput> {
    let mut options = RenderOptions::for_scene(scene);
    (options.width, options.height) = (a.width, a.height);
    let pixels = u64::from(a.width) * u64::from(a.height);
    let photons = u64::from(sppm.photons_per_iteration);
    let stages = sppm_stage_seconds(
        gpu,
        scene,
        &options,
        sppm,
        (iterations.0, iterations.1, a.repeats),
    )?;
    let (pixel_copy, photon_copy) = (
        copy_pass_seconds(gpu, pixels, a.repeats)?,
        copy_pass_seconds(gpu, photons, a.repeats)?,
    );
    let stages: Vec<StageRow> = stages
        .into_iter()
        .map(|s| {
            let (records, unit, copy) = match s.name.as_str() {
                "trace photons" => (photons, "photon paths", photon_copy),
                "build map" => (photons, "photons emitted", photon_copy),
                "gather + update" => (pixels, "queries", pixel_copy),
                n if n.starts_with("eye paths") => (pixels, "eye paths", pixel_copy),
                _ => (pixels, "pixels", pixel_copy),
            };
            StageRow {
                per_second: records as f64 / s.seconds,
                copy_passes: s.seconds / copy,
                stage: s.name,
                records,
                unit,
                seconds: s.seconds,
                copy_seconds: copy,
            }
        })
        .collect();
    let photon_paths_per_second = stages
        .iter()
        .find(|s| s.stage == "trace photons")
        .map_or(f64::NAN, |s| s.per_second);

    let mut direct_scene = scene.clone();
    direct_scene.render.shadow_rays = a.shadow_rays;
    let mut direct = options.clone().direct_only();
    direct.spp = a.spp;
    let seconds = render_seconds(gpu, &direct_scene, &direct, a.repeats)?;
    let paths = pixels * u64::from(a.spp);
    let path_copy = copy_pass_seconds(gpu, paths, a.repeats)?;
    Ok(SceneThroughput {
        scene: name.to_string(),
        diffuse: scene
            .materials
            .iter()
            .all(|m| matches!(m, Material::Diffuse { .. } | Material::Emitter { .. })),
        stages,
        direct: DirectRow {
            spp: a.spp,
            shadow_rays: a.shadow_rays,
            seconds,
            eye_paths_per_second: paths as f64 / seconds,
            copy_passes: seconds / path_copy,
            mitsuba_seconds: None,
            ratio: None,
        },
        photon_paths_per_second,
        ptracer_paths_per_second: None,
        photon_ratio: None,
        mitsuba: None,
    })
}

fn print_report(r: &ThroughputReport) {
    println!("{}", r.command);
    println!("{} ({})", r.provenance.renderer, r.provenance.gl_version);
    println!(
        "{} x {}, SPPM at its defaults ({} photons an iteration; stage times from runs of {} and {} iterations differenced)",
        r.width, r.height, r.sppm_photons_per_iteration, r.iterations[0], r.iterations[1]
    );
    for s in &r.scenes {
        println!("\n{}{}", s.scene, if s.diffuse { " (diffuse)" } else { "" });
        println!(
            "  {:<20} {:>9} {:>9} {:>14} {:>9} {:>9}",
            "stage", "records", "ms", "rate /s", "copy ms", "x copy"
        );
        for st in &s.stages {
            println!(
                "  {:<20} {:>9} {:>9.2} {:>9.3e} {:<4} {:>9.3} {:>9.1}",
                st.stage,
                st.records,
                st.seconds * 1e3,
                st.per_second,
                short_unit(st.unit),
                st.copy_seconds * 1e3,
                st.copy_passes
            );
        }
        let d = &s.direct;
        println!(
            "  direct light, {} spp x {} shadow rays: {:.3} s, {:.3e} eye paths/s, {:.0} copy passes; Mitsuba direct {}",
            d.spp,
            d.shadow_rays,
            d.seconds,
            d.eye_paths_per_second,
            d.copy_passes,
            match (d.mitsuba_seconds, d.ratio) {
                (Some(m), Some(x)) => format!("{m:.3} s (photonmap {x:.2}x its time)"),
                _ => "-".into(),
            }
        );
        println!(
            "  photon paths/s {:.3e}; Mitsuba ptracer light paths/s {}",
            s.photon_paths_per_second,
            match (s.ptracer_paths_per_second, s.photon_ratio) {
                (Some(p), Some(x)) => format!("{p:.3e} (photonmap {x:.3}x its rate)"),
                _ => "-".into(),
            }
        );
    }
}

fn short_unit(unit: &str) -> &str {
    match unit {
        "photon paths" => "pht",
        "photons emitted" => "pht",
        "queries" => "qry",
        "eye paths" => "eye",
        _ => "px",
    }
}
