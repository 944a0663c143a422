//! `--method vcm`: one view, iterations until --iterations or --time.

use std::path::PathBuf;

use anyhow::{bail, Result};

use photonmap::gpu::Platform;
use photonmap::render::{self, StopReason};

use super::args::Format;
use super::args::{RenderArgs, Start};
use super::observer::CliObserver;
use super::output::{print_explain, provenance, write_image_sets, Report};
use crate::cli::progress::Work;

/// `--method vcm`: one view, iterations until --iterations or --time.
pub(super) fn run(args: &RenderArgs, platform: Platform) -> Result<()> {
    let Start {
        outputs,
        loaded,
        options,
    } = args.start()?;
    let scene = &loaded.scene;
    if let Some(dir) = &args.vcm.vcm_techniques {
        check_techniques_dir(dir)?;
    }
    let gpu = crate::cli::gpu(platform)?;
    let mut provenance = provenance(loaded.provenance, &gpu, "vcm", &options);
    let work = Work::Iterations {
        iterations: args.sppm.iteration_limit(),
        seconds: args.sppm.time,
    };
    let mut observer = CliObserver::new(args, scene, &outputs, work, &provenance);
    let render::Method::Vcm(vcm) = &options.method else {
        unreachable!("--method vcm gives Method::Vcm");
    };
    let result = render::vcm::render_vcm(
        &gpu,
        scene,
        &options,
        vcm,
        args.vcm.vcm_techniques.is_some(),
        &mut observer,
    );
    let out = observer.finish_with(result, outputs.images(), &provenance)?;
    provenance.iterations = Some(out.iterations);
    provenance.photons_emitted = Some(out.light_paths);
    // The image and the technique images, all written or none.
    let technique_outputs: Vec<[(PathBuf, Format); 1]> = match &args.vcm.vcm_techniques {
        Some(dir) => {
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("--vcm-techniques {}: {e}", dir.display()))?;
            render::vcm::TECHNIQUES
                .iter()
                .map(|name| {
                    [(
                        dir.join(name.replace([' ', '-'], "_") + ".exr"),
                        Format::Exr,
                    )]
                })
                .collect()
        }
        None => Vec::new(),
    };
    let mut sets = vec![(&out.image, outputs.images())];
    sets.extend(
        out.techniques
            .iter()
            .zip(&technique_outputs)
            .map(|(image, o)| (image, &o[..])),
    );
    let written = write_image_sets(&sets, &provenance)?;
    if args.json {
        crate::cli::print_json(&Report {
            provenance: &provenance,
            outputs: written.clone(),
            figures: serde_json::json!({
                "method": "vcm",
                "vcm_mode": vcm.mode,
                "iterations": out.iterations,
                "stopped_by": out.stopped_by,
                "light_paths": out.light_paths,
                "light_paths_per_iteration": vcm.light_paths,
                "connections": vcm.connections,
                "camera_continuation": vcm.camera_continuation_in_use(),
                "merge_start_pixels": vcm.start_pixels,
                "max_path_length": vcm.max_segments,
                "initial_radius": out.initial_radius,
                "final_radius": out.final_radius,
                "alpha": vcm.alpha,
                "timings": out.timings,
            }),
        })?;
    }
    if args.explain {
        print_explain(&out.explain);
    }
    if !args.quiet {
        eprint!("{}", out.timings.table());
        eprintln!(
            "VCM ({}): {} iterations in {:.1} s (stopped by {}), {} light paths traced, merging radius {} -> {:.5}",
            vcm.mode.name(),
            out.iterations,
            out.timings.wall_seconds,
            match out.stopped_by {
                StopReason::Iterations => "its iterations",
                StopReason::Time => "--time",
            },
            out.light_paths,
            out.initial_radius,
            out.final_radius
        );
        for (p, _) in &written {
            eprintln!("wrote {p}");
        }
    }
    Ok(())
}

/// Refuses, before the render, a `--vcm-techniques` folder that cannot be
/// made: a file of that name, or one whose nearest existing ancestor is not
/// a folder.
fn check_techniques_dir(dir: &std::path::Path) -> Result<()> {
    let existing = dir
        .ancestors()
        .find(|p| p.as_os_str().is_empty() || p.exists());
    match existing {
        Some(p) if p.as_os_str().is_empty() || p.is_dir() => Ok(()),
        Some(p) if p == dir => bail!("--vcm-techniques {}: not a folder", dir.display()),
        Some(p) => bail!(
            "--vcm-techniques {}: {} is not a folder",
            dir.display(),
            p.display()
        ),
        None => Ok(()),
    }
}
