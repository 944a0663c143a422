//! The command line: `photonmap render`, `photonmap info`.

mod cli;

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{bail, Result};
use clap::{Parser, Subcommand};

use photonmap::gpu::{EglPlatform, Gpu};
use photonmap::photon::{BuildMethod, VertexFeed};
use photonmap::reference::knn::{software_image, SoftwareEstimate};
use photonmap::render::Image;
use photonmap::render::{
    self, EstimateMode, EstimateOptions, GlobalIllumination, RenderOptions, SnapshotEvery,
    Snapshots,
};
use photonmap::scene::load_scene;

#[derive(Parser)]
#[command(
    name = "photonmap",
    version,
    about = "Headless GPU photon mapping after Purcell et al. 2003, on OpenGL fragment passes"
)]
struct Cli {
    /// EGL platform: auto (a GPU's device platform when present, else Mesa surfaceless), surfaceless, device.
    #[arg(long, value_enum, default_value_t = EglPlatform::Auto, global = true)]
    egl: EglPlatform,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene file to a PNG (sRGB) and optionally an EXR (linear float RGB).
    Render {
        /// Scene file (TOML; see README.md).
        scene: PathBuf,
        /// Output PNG path (with --camera-path: the frames go to --out instead).
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// Also write linear float RGB to this OpenEXR path.
        #[arg(long)]
        exr: Option<PathBuf>,
        /// Random seed: the same seed on the same driver gives the same image.
        #[arg(long, default_value_t = 1)]
        seed: u32,
        /// Eye samples per pixel: 1 (the paper) through the pixel centre; more are
        /// stratified, jittered and box-filtered, each with its own estimate (1..=1024).
        #[arg(long, default_value_t = 1)]
        spp: u32,
        /// Image width in pixels (default: the scene's).
        #[arg(long)]
        width: Option<u32>,
        /// Image height in pixels (default: the scene's).
        #[arg(long)]
        height: Option<u32>,
        /// No progress bar and no timing table on stderr.
        #[arg(long)]
        quiet: bool,
        /// Print the per-stage timings as JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Photon-map build for indirect light and caustics.
        #[arg(long, value_enum, default_value_t = BuildMethod::Bitonic)]
        build: BuildMethod,
        /// Direct light and specular paths only: no photons, no radiance estimate.
        #[arg(long)]
        direct_only: bool,
        /// Stencil routing: each cell holds m x m photons (1..=16).
        #[arg(long, default_value_t = 4)]
        stencil_m: u32,
        /// Stencil routing: how photons reach the vertex stage.
        #[arg(long, value_enum, default_value_t = VertexFeed::VertexFetch)]
        feed: VertexFeed,
        /// The paper's 2003 constraints: a texture of random numbers, read-back before routing.
        #[arg(long)]
        faithful: bool,
        /// Radiance estimate tiles of N x N pixels, each stopped by occlusion query (0: full screen).
        #[arg(long, default_value_t = 16)]
        tile: u32,
        /// Full screen behind a per-pixel stencil mask of finished pixels, refreshed every N passes.
        #[arg(long, value_name = "N")]
        mask: Option<u32>,
        /// Radiance estimate steps per pixel per pass (1..=100000).
        #[arg(long, default_value_t = 64)]
        budget: u32,
        /// Write the running estimate as numbered PNGs (and snapshots.json) into DIR.
        #[arg(long, value_name = "DIR")]
        snapshots: Option<PathBuf>,
        /// Snapshot interval: seconds ("0.5s") or passes ("10").
        #[arg(long, default_value = "0.5s")]
        every: String,
        /// List every pass that runs and every pass skipped, with why.
        #[arg(long)]
        explain: bool,
        /// Render a fly-through: a TOML of key cameras (and `frames = N`), all on one
        /// photon map, into --out as frame_NNNN.png.
        #[arg(long, value_name = "TOML")]
        camera_path: Option<PathBuf>,
        /// The folder for --camera-path frames.
        #[arg(long, value_name = "DIR")]
        out: Option<PathBuf>,
        /// Trace all max_bounces photon bounces even when none is left alive.
        #[arg(long)]
        all_bounces: bool,
        /// Scenes that store caustics only: emit photons in every direction
        /// instead of aiming them by projection maps (to compare).
        #[arg(long)]
        no_projection_map: bool,
        /// Also write the software reference (the paper's figure 7c: the same eye
        /// paths and photons, the estimate on the CPU) to this PNG.
        #[arg(long, value_name = "PNG")]
        reference_software: Option<PathBuf>,
        /// The software reference's estimate: Jensen's kd-tree or the CPU kNN-grid.
        #[arg(long, value_enum, default_value_t = SoftwareEstimate::KdTree)]
        reference_estimate: SoftwareEstimate,
    },
    /// Trace a scene's photons and build its photon map; report counts, passes and times.
    Photons {
        scene: PathBuf,
        /// Photon-map build: bitonic sort + binary search, or stencil routing.
        #[arg(long, value_enum, default_value_t = BuildMethod::Bitonic)]
        build: BuildMethod,
        /// Stencil routing: each cell holds m x m photons (1..=16).
        #[arg(long, default_value_t = 4)]
        stencil_m: u32,
        /// Stencil routing: how photons reach the vertex stage.
        #[arg(long, value_enum, default_value_t = VertexFeed::VertexFetch)]
        feed: VertexFeed,
        /// The paper's 2003 constraints: a texture of random numbers, read-back before routing.
        #[arg(long)]
        faithful: bool,
        /// Scenes that store caustics only: emit photons in every direction
        /// instead of aiming them by projection maps (to compare).
        #[arg(long)]
        no_projection_map: bool,
        #[arg(long, default_value_t = 1)]
        seed: u32,
        /// As JSON on stdout.
        #[arg(long)]
        json: bool,
    },
    /// Compare two linear EXR images (the second is the reference): RMSE,
    /// relative MSE, SSIM, and optionally a false-colour difference image.
    Compare {
        image: PathBuf,
        reference: PathBuf,
        /// Only pixels where this PNG (same size) is bright (> 50%) count.
        #[arg(long)]
        mask: Option<PathBuf>,
        /// Write |a - b| / (|b| + 0.01) as a false-colour PNG (black 0 .. red >= 1).
        #[arg(long, value_name = "PNG")]
        diff: Option<PathBuf>,
        #[arg(long)]
        json: bool,
    },
    /// Render a converged reference of a scene (more photons, larger k, several
    /// eye samples, many seeds averaged) as EXR, with its command and residual noise.
    Reference {
        scene: PathBuf,
        /// Output EXR (default: reference_images/<scene>.converged.exr; a .json goes beside it).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Render at 1/scale of the scene's resolution.
        #[arg(long, default_value_t = 2)]
        scale: u32,
        /// Photons stored x this; k x its square root.
        #[arg(long, default_value_t = 8)]
        photons_factor: u32,
        #[arg(long, default_value_t = 8)]
        seeds: u32,
        #[arg(long, default_value_t = 4)]
        spp: u32,
    },
    /// Reproduce the paper's tables and figures into results/<renderer>/ (or --out).
    Tables {
        /// Output folder (default: results/<renderer>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// A reduced run for CI: quarter resolution, one run, fewer sizes and modes.
        #[arg(long)]
        quick: bool,
        /// The paper's 2003 constraints (random-number texture, read-back, no compaction).
        #[arg(long)]
        faithful: bool,
        /// Runs per Table 1 cell (median and spread quoted).
        #[arg(long, default_value_t = 3)]
        runs: u32,
        #[arg(long)]
        json: bool,
        #[arg(long)]
        quiet: bool,
    },
    /// Benchmarks (commands, not tests): `bench build`.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
    /// Print the EGL and GL implementation and the limits this program relies on.
    Info {
        /// As JSON on stdout.
        #[arg(long)]
        json: bool,
    },
}

#[derive(Subcommand)]
enum BenchCommand {
    /// The stress suite: scale and place, sizes, crowding, grids, search edges,
    /// difficult paths, the furnace; one JSON object per case with --json.
    Stress {
        /// Only the cases that take seconds.
        #[arg(long)]
        quick: bool,
        #[arg(long)]
        json: bool,
        #[arg(long)]
        quiet: bool,
    },
    /// Run time against error around a scene's defaults (photons, k, maximum
    /// radius, shadow rays, build, tiling, samples), against its converged
    /// reference; CSV, JSON, SVG and PNG plots of the Pareto front.
    Accuracy {
        #[arg(long)]
        scene: PathBuf,
        /// The converged reference (default: reference_images/<scene>.converged.exr).
        #[arg(long)]
        reference: Option<PathBuf>,
        /// Output folder (default: results/<renderer>/accuracy/<scene>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// A small sweep.
        #[arg(long)]
        quick: bool,
        #[arg(long)]
        json: bool,
        #[arg(long)]
        quiet: bool,
    },
    /// Whether the stencil test skips fragment work on this driver (the
    /// computation mask): an expensive pass with 0%, 50% and 90% of pixels masked.
    Mask {
        #[arg(long, default_value_t = 512)]
        size: u32,
        #[arg(long, default_value_t = 200)]
        iterations: i32,
        #[arg(long)]
        json: bool,
    },
    /// Photon-map builds for n = 2^min .. 2^max synthetic photons: bitonic passes,
    /// time per pass against a copy pass, binary search, stencil routing with and
    /// without read-back.
    Build {
        #[arg(long, default_value_t = 10)]
        min_log2: u32,
        #[arg(long, default_value_t = 20)]
        max_log2: u32,
        /// Stencil routing m (the paper: a 1024 x 1024 buffer of about 40^3 cells).
        #[arg(long, default_value_t = 4)]
        stencil_m: u32,
        #[arg(long)]
        json: bool,
        #[arg(long)]
        quiet: bool,
    },
}

/// "0.5s" -> every half second of estimate; "10" -> every 10 passes.
fn parse_every(text: &str) -> Result<SnapshotEvery> {
    let t = text.trim();
    if let Some(secs) = t.strip_suffix('s') {
        match secs.parse::<f64>() {
            Ok(v) if v > 0.0 && v.is_finite() => return Ok(SnapshotEvery::Seconds(v)),
            _ => bail!("--every {text}: seconds must be a positive number, as in 0.5s"),
        }
    }
    match t.parse::<u32>() {
        Ok(n) if n >= 1 => Ok(SnapshotEvery::Passes(n)),
        _ => bail!("--every {text}: give seconds (0.5s) or a number of passes (10, at least 1)"),
    }
}

fn check_output(path: &Path, extension: &str, flag: &str) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !ext.eq_ignore_ascii_case(extension) {
        bail!(
            "{flag} {}: the file name must end in .{extension}",
            path.display()
        );
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!(
            "{flag} {}: the folder {} does not exist",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Photons {
            scene,
            build,
            stencil_m,
            feed,
            faithful,
            no_projection_map,
            seed,
            json,
        } => {
            let scene = load_scene(&scene)?;
            let gpu = Gpu::new(cli.egl)?;
            let options = cli::photons::PhotonOptions {
                seed,
                build,
                faithful,
                feed,
                stencil_block: stencil_m,
                projection_maps: !no_projection_map,
            };
            let report = cli::photons::trace_and_build(&gpu, &scene, &options)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                cli::photons::print_report(&report);
            }
            Ok(())
        }
        Command::Bench {
            which:
                BenchCommand::Build {
                    min_log2,
                    max_log2,
                    stencil_m,
                    json,
                    quiet,
                },
        } => {
            let gpu = Gpu::new(cli.egl)?;
            let bench = cli::bench::run_build_bench(&gpu, min_log2, max_log2, stencil_m, !quiet)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&bench)?);
            } else {
                cli::bench::print_build_bench(&bench);
            }
            Ok(())
        }
        Command::Bench {
            which:
                BenchCommand::Mask {
                    size,
                    iterations,
                    json,
                },
        } => {
            if !(16..=8192).contains(&size) || !(1..=100_000).contains(&iterations) {
                bail!("--size {size} --iterations {iterations}: the allowed ranges are 16..=8192 and 1..=100000");
            }
            let gpu = Gpu::new(cli.egl)?;
            let rows = photonmap::photon::bench::bench_mask(&gpu, size, iterations)?;
            if json {
                let caps = gpu.capabilities();
                println!(
                    "{}",
                    serde_json::json!({ "renderer": caps.gl_renderer, "size": size, "iterations": iterations, "rows": rows })
                );
            } else {
                println!(
                    "{:>8} {:>11} {:>8} {:>10} {:>9}",
                    "masked", "where", "stencil", "wall ms", "relative"
                );
                for r in &rows {
                    let place = if r.contiguous { "contiguous" } else { "spread" };
                    println!(
                        "{:>7.0}% {place:>11} {:>8} {:>10.2} {:>9.3}",
                        r.masked_fraction * 100.0,
                        r.stencil_test,
                        r.wall_seconds * 1e3,
                        r.relative
                    );
                }
            }
            Ok(())
        }
        Command::Tables {
            out,
            quick,
            faithful,
            runs,
            json,
            quiet,
        } => {
            let gpu = Gpu::new(cli.egl)?;
            let options = cli::tables::TablesOptions {
                out,
                quick,
                faithful,
                runs,
            };
            let progress = |msg: &str| {
                if !quiet {
                    eprintln!("{msg}");
                }
            };
            let (report, dir) = cli::tables::run_tables(&gpu, &options, &progress)?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
                print!("{}", cli::tables::markdown(&report));
                eprintln!("wrote {}", dir.display());
            }
            Ok(())
        }
        Command::Compare {
            image,
            reference,
            mask,
            diff,
            json,
        } => {
            if let Some(d) = &diff {
                check_output(d, "png", "--diff")?;
            }
            let a = Image::read_exr(&image).map_err(anyhow::Error::msg)?;
            let b = Image::read_exr(&reference).map_err(anyhow::Error::msg)?;
            let mask = match &mask {
                None => None,
                Some(path) => {
                    let m = ::image::open(path)
                        .map_err(|e| {
                            anyhow::anyhow!("cannot read the mask {}: {e}", path.display())
                        })?
                        .to_luma8();
                    if m.dimensions() != (a.width, a.height) {
                        bail!(
                            "--mask {}: {} x {} pixels, the images are {} x {}",
                            path.display(),
                            m.width(),
                            m.height(),
                            a.width,
                            a.height
                        );
                    }
                    Some(m.pixels().map(|p| p[0] > 127).collect::<Vec<bool>>())
                }
            };
            let metrics =
                photonmap::metrics::compare(&a, &b, mask.as_deref()).map_err(anyhow::Error::msg)?;
            if let Some(d) = &diff {
                let png = photonmap::metrics::false_colour(&a, &b)
                    .png_bytes()
                    .map_err(anyhow::Error::msg)?;
                render::image::write_atomically(d, &png).map_err(anyhow::Error::msg)?;
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&metrics)?);
            } else {
                println!("pixels compared  {}", metrics.pixels_compared);
                println!("RMSE (linear)    {:.6}", metrics.rmse);
                println!("relative MSE     {:.6}", metrics.rel_mse);
                println!("SSIM (luminance) {:.6}", metrics.ssim);
            }
            Ok(())
        }
        Command::Reference {
            scene: scene_path,
            out,
            scale,
            photons_factor,
            seeds,
            spp,
        } => {
            let scene = load_scene(&scene_path)?;
            let out = out.unwrap_or_else(|| cli::accuracy::default_reference(&scene_path));
            check_output(&out, "exr", "--out")?;
            let gpu = Gpu::new(cli.egl)?;
            let command = format!(
                "photonmap reference {} --scale {scale} --photons-factor {photons_factor} --seeds {seeds} --spp {spp}",
                scene_path.display()
            );
            let options = cli::accuracy::ReferenceOptions {
                scale,
                photons_factor,
                seeds,
                spp,
            };
            let (img, info) =
                cli::accuracy::make_reference(&gpu, &scene, &options, command, &|m: &str| {
                    eprintln!("{m}")
                })?;
            cli::accuracy::write_reference(&img, &info, &out)?;
            eprintln!(
                "wrote {} (residual RMSE {:.6})",
                out.display(),
                info.residual_rmse
            );
            Ok(())
        }
        Command::Bench {
            which:
                BenchCommand::Accuracy {
                    scene: scene_path,
                    reference,
                    out,
                    quick,
                    json,
                    quiet,
                },
        } => {
            let scene = load_scene(&scene_path)?;
            let reference =
                reference.unwrap_or_else(|| cli::accuracy::default_reference(&scene_path));
            if !reference.is_file() {
                bail!(
                    "no converged reference at {}: make one with `photonmap reference {}`",
                    reference.display(),
                    scene_path.display()
                );
            }
            let gpu = Gpu::new(cli.egl)?;
            let progress = |m: &str| {
                if !quiet {
                    eprintln!("{m}");
                }
            };
            let report = cli::accuracy::bench_accuracy(&gpu, &scene, &reference, quick, &progress)?;
            let stem = scene_path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default();
            let dir = out.unwrap_or_else(|| {
                cli::tables::default_out(&report.renderer)
                    .join("accuracy")
                    .join(&stem)
            });
            std::fs::create_dir_all(&dir)?;
            let write = |name: &str, bytes: &[u8]| {
                render::image::write_atomically(&dir.join(name), bytes).map_err(anyhow::Error::msg)
            };
            write("accuracy.csv", cli::accuracy::csv(&report).as_bytes())?;
            write(
                "accuracy.json",
                serde_json::to_string_pretty(&report)?.as_bytes(),
            )?;
            write("accuracy.svg", cli::accuracy::svg_plot(&report).as_bytes())?;
            write("accuracy.png", &cli::accuracy::png_plot(&report))?;
            if json {
                println!("{}", serde_json::to_string_pretty(&report)?);
            } else {
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
            }
            Ok(())
        }
        Command::Bench {
            which: BenchCommand::Stress { quick, json, quiet },
        } => {
            let gpu = Gpu::new(cli.egl)?;
            let progress = |m: &str| {
                if !quiet {
                    eprintln!("{m}");
                }
            };
            let cases = photonmap::stress::run(&gpu, quick, &progress);
            if json {
                for c in &cases {
                    println!("{}", serde_json::to_string(c)?);
                }
            } else {
                for c in &cases {
                    println!(
                        "{:<8} {:<70} {:>12.5} {:>7.2} s  {}",
                        format!("{:?}", c.outcome).to_lowercase(),
                        c.name,
                        c.value,
                        c.seconds,
                        c.message
                    );
                }
            }
            if cases
                .iter()
                .any(|c| c.outcome == photonmap::stress::Outcome::Fail)
            {
                bail!("some stress cases failed");
            }
            Ok(())
        }
        Command::Info { json } => {
            let gpu = Gpu::new(cli.egl)?;
            let caps = gpu.capabilities();
            if json {
                println!("{}", serde_json::to_string_pretty(&caps)?);
            } else {
                println!("EGL platform      {}", caps.egl_platform);
                println!(
                    "EGL vendor        {} (EGL {})",
                    caps.egl_vendor, caps.egl_version
                );
                println!("GL vendor         {}", caps.gl_vendor);
                println!("GL renderer       {}", caps.gl_renderer);
                println!(
                    "GL version        {} (context {})",
                    caps.gl_version, caps.context_version
                );
                println!("GLSL version      {}", caps.glsl_version);
                println!("max texture size  {}", caps.max_texture_size);
                println!("max draw buffers  {}", caps.max_draw_buffers);
                println!(
                    "point size range  {} .. {}",
                    caps.point_size_range[0], caps.point_size_range[1]
                );
                println!("stencil bits      {}", caps.stencil_bits);
                println!("timer query bits  {}", caps.timer_query_bits);
                println!("occlusion query bits {}", caps.occlusion_query_bits);
            }
            Ok(())
        }
        Command::Render {
            scene,
            output,
            exr,
            seed,
            spp,
            width,
            height,
            quiet,
            json,
            build,
            direct_only,
            stencil_m,
            feed,
            faithful,
            tile,
            mask,
            budget,
            snapshots,
            every,
            explain,
            all_bounces,
            no_projection_map,
            camera_path,
            out,
            reference_software,
            reference_estimate,
        } => {
            if let Some(p) = &reference_software {
                check_output(p, "png", "--reference-software")?;
                if direct_only {
                    bail!("--reference-software needs photons: drop --direct-only");
                }
            }
            let output = match (&output, &camera_path, &out) {
                (Some(o), None, _) => o.clone(),
                (None, Some(_), Some(dir)) => {
                    if !dir.is_dir() {
                        bail!("--out {}: the folder does not exist", dir.display());
                    }
                    // Not written: each frame goes to the folder as it is made.
                    dir.join("frames.png")
                }
                (None, Some(_), None) => bail!("--camera-path needs --out DIR for its frames"),
                (Some(_), Some(_), _) => bail!(
                    "give either -o (one image) or --camera-path with --out (frames), not both"
                ),
                (None, None, _) => bail!("-o OUTPUT.png is required"),
            };
            check_output(&output, "png", "-o")?;
            if let Some(e) = &exr {
                check_output(e, "exr", "--exr")?;
            }
            for (name, v) in [("--width", width), ("--height", height)] {
                if let Some(v) = v {
                    if !(1..=16384).contains(&v) {
                        bail!("{name} {v}: the allowed range is 1..=16384");
                    }
                }
            }
            if !(1..=16).contains(&stencil_m) {
                bail!("--stencil-m {stencil_m}: the allowed range is 1..=16 (m^2 slots must fit 8 stencil bits)");
            }
            if !(1..=1024).contains(&spp) {
                bail!("--spp {spp}: the allowed range is 1..=1024");
            }
            if !(1..=100_000).contains(&budget) {
                bail!("--budget {budget}: the allowed range is 1..=100000");
            }
            if tile > 255 {
                bail!("--tile {tile}: the allowed range is 0 (full screen) or 1..=255 (llvmpipe's largest point size)");
            }
            let every = parse_every(&every)?;
            if let Some(dir) = &snapshots {
                if !dir.is_dir() {
                    bail!("--snapshots {}: the folder does not exist", dir.display());
                }
            }
            let scene = load_scene(&scene)?;
            let ratio = scene.offset_ratio();
            if ratio > 1000.0 && !quiet {
                eprintln!(
                    "warning: coordinates reach {ratio:.0} x the scene's size; 32-bit floats resolve them only to ~{:.0e} of it, so fine detail (sharp caustics) may blur: move the scene near the origin",
                    ratio * f32::EPSILON
                );
            }
            let mut options = RenderOptions::for_scene(&scene);
            options.seed = seed;
            options.spp = spp;
            options.width = width.unwrap_or(options.width);
            options.height = height.unwrap_or(options.height);
            let mode = match (mask, tile) {
                (Some(n), _) => EstimateMode::Masked { every: n.max(1) },
                (None, 0) => EstimateMode::FullScreen,
                (None, t) => EstimateMode::Tiled { tile: t },
            };
            options.global = (!direct_only).then(|| GlobalIllumination {
                build,
                stencil_block: stencil_m,
                feed,
                faithful,
                estimate: EstimateOptions {
                    mode,
                    budget,
                    ..EstimateOptions::default()
                },
                snapshots: snapshots.map(|dir| Snapshots { dir, every }),
                all_bounces,
                projection_maps: !no_projection_map,
            });
            let gpu = Gpu::new(cli.egl)?;
            let bar = if quiet {
                indicatif::ProgressBar::hidden()
            } else {
                let b = indicatif::ProgressBar::new(1);
                b.set_style(
                    indicatif::ProgressStyle::with_template(
                        "{msg} [{bar:40}] {pos}/{len} {elapsed}",
                    )
                    .expect("valid template")
                    .progress_chars("=> "),
                );
                b.set_message(format!(
                    "{} {}x{}",
                    scene.name, options.width, options.height
                ));
                b
            };
            let progress = |stage: &str, done: u64, total: u64| {
                bar.set_message(format!("{} {}", scene.name, stage));
                bar.set_length(total.max(1));
                bar.set_position(done);
            };
            let cameras = match &camera_path {
                Some(p) => photonmap::scene::camera_path::load_camera_path(p, &scene.camera)?,
                None => vec![scene.camera.clone()],
            };
            let frame_dir = out.clone();
            let mut frame_times = Vec::new();
            let frame_clock = std::time::Instant::now();
            let mut on_frame = |i: usize, img: &Image| -> Result<(), String> {
                if let Some(dir) = &frame_dir {
                    let file = dir.join(format!("frame_{i:04}.png"));
                    render::image::write_atomically(&file, &img.png_bytes()?)?;
                    frame_times.push(frame_clock.elapsed().as_secs_f64());
                }
                Ok(())
            };
            let out =
                render::render_views(&gpu, &scene, &options, &cameras, &progress, &mut on_frame)?;
            if let Some(dir) = &frame_dir {
                let index = serde_json::json!({ "frames": cameras.len(), "seconds_since_start": frame_times });
                render::image::write_atomically(
                    &dir.join("frames.json"),
                    index.to_string().as_bytes(),
                )
                .map_err(anyhow::Error::msg)?;
            }
            bar.finish_and_clear();
            if out.image.has_non_finite() {
                bail!("the render produced NaN or infinite pixels: nothing was written (a bug; please report it with the scene)");
            }
            let png = out.image.png_bytes().map_err(anyhow::Error::msg)?;
            let exr_bytes = exr
                .as_ref()
                .map(|_| out.image.exr_bytes())
                .transpose()
                .map_err(anyhow::Error::msg)?;
            if camera_path.is_none() {
                render::image::write_atomically(&output, &png).map_err(anyhow::Error::msg)?;
            }
            if let (Some(path), Some(bytes)) = (&exr, exr_bytes) {
                render::image::write_atomically(path, &bytes).map_err(anyhow::Error::msg)?;
            }
            if json {
                println!("{}", serde_json::to_string_pretty(&out.timings)?);
            }
            if let Some(path) = &reference_software {
                let wall = std::time::Instant::now();
                let img = software_image(&out.state, &scene, reference_estimate)
                    .ok_or_else(|| anyhow::anyhow!("no photon map to estimate from"))?;
                let png = img.png_bytes().map_err(anyhow::Error::msg)?;
                render::image::write_atomically(path, &png).map_err(anyhow::Error::msg)?;
                if !quiet {
                    eprintln!(
                        "software reference ({reference_estimate:?}) in {:.2} s: wrote {}",
                        wall.elapsed().as_secs_f64(),
                        path.display()
                    );
                }
            }
            if explain {
                for l in &out.explain {
                    let what = if l.ran { "run " } else { "skip" };
                    eprintln!("{what} {:<34} {:>6} passes  {}", l.stage, l.passes, l.why);
                }
            }
            if !quiet {
                eprint!("{}", out.timings.table());
                if let Some(e) = &out.estimate {
                    eprintln!(
                        "radiance estimate: {} passes, {} of {} pixels searched, {} tile draws of {} tiles",
                        e.passes,
                        e.query_pixels,
                        options.width as u64 * options.height as u64,
                        e.tile_draws,
                        e.tiles
                    );
                }
                eprintln!("wrote {}", output.display());
            }
            Ok(())
        }
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
