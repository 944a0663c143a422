//! `--method vcm`: one view, iterations until --iterations or --time.

use anyhow::Result;

use photonmap::gpu::Platform;
use photonmap::render::{self, StopReason};

use super::args::{RenderArgs, Start};
use super::observer::CliObserver;
use super::output::{print_explain, provenance, write_images, Report};
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
    let result = render::vcm::render_vcm(&gpu, scene, &options, vcm, &mut observer);
    let out = observer.finish_with(result, outputs.images(), &provenance)?;
    provenance.iterations = Some(out.iterations);
    provenance.photons_emitted = Some(out.light_paths);
    let mut written = write_images(&out.image, outputs.images(), &provenance)?;
    if let Some(dir) = &args.vcm.vcm_techniques {
        written.extend(write_techniques(dir, &out.techniques, &provenance)?);
    }
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
/// made: a file of that name, or a parent that is not a folder.
fn check_techniques_dir(dir: &std::path::Path) -> Result<()> {
    if dir.exists() {
        anyhow::ensure!(
            dir.is_dir(),
            "--vcm-techniques {}: not a folder",
            dir.display()
        );
        return Ok(());
    }
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(p) = parent {
        anyhow::ensure!(
            p.is_dir(),
            "--vcm-techniques {}: its parent {} is not a folder",
            dir.display(),
            p.display()
        );
    }
    Ok(())
}

/// `--vcm-techniques DIR`: each technique's image as DIR/<technique>.exr,
/// all written or none.
fn write_techniques(
    dir: &std::path::Path,
    techniques: &[photonmap::render::Image],
    provenance: &photonmap::provenance::Provenance,
) -> Result<Vec<(String, super::args::Format)>> {
    use anyhow::Context;
    let format = super::args::Format::Exr;
    let mut files = Vec::new();
    for (name, image) in render::vcm::TECHNIQUES.iter().zip(techniques) {
        let path = dir.join(name.replace([' ', '-'], "_") + ".exr");
        anyhow::ensure!(
            !image.has_non_finite(),
            "{name} produced NaN or infinite pixels: nothing was written (a bug; please report it with the scene)"
        );
        files.push((path, format.encode(image, provenance)?));
    }
    std::fs::create_dir_all(dir).with_context(|| format!("making {}", dir.display()))?;
    let refs: Vec<(&std::path::Path, &[u8])> = files
        .iter()
        .map(|(p, b)| (p.as_path(), b.as_slice()))
        .collect();
    photonmap::image::write_all_atomically(&refs)?;
    Ok(files
        .iter()
        .map(|(p, _)| (p.display().to_string(), format))
        .collect())
}
