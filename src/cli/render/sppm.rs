//! `--method sppm`: one view, iterations until --iterations or --time.

use anyhow::{bail, Result};

use photonmap::gpu::Platform;
use photonmap::render::{self, StopReason, WithPhotons};

use super::args::{RenderArgs, Start};
use super::observer::CliObserver;
use super::output::{print_explain, provenance, write_images, Report};
use crate::cli::progress::Work;

/// `--method sppm`: one view, iterations until --iterations or --time.
pub(super) fn run(args: &RenderArgs, platform: Platform) -> Result<()> {
    let Start {
        outputs,
        loaded,
        options,
    } = args.start()?;
    let scene = &loaded.scene;
    let gpu = crate::cli::gpu(platform)?;
    let mut provenance = provenance(loaded.provenance, &gpu, "sppm", &options);
    if args.adaptive
        && args.sppm.iterations.is_none()
        && args.sppm.time.is_some()
        && args.sppm.adaptive_pilot.is_none()
    {
        bail!("--adaptive with --time alone cannot take its pilot as an eighth of the iterations: give --adaptive-pilot N (iterations at every pixel before the plan) or --iterations");
    }
    let work = Work::Iterations {
        iterations: args.sppm.iteration_limit(),
        seconds: args.sppm.time,
    };
    let mut observer = CliObserver::new(args, scene, &outputs, work, &provenance);
    let render::Method::Sppm(WithPhotons { method: sppm, .. }) = &options.method else {
        unreachable!("--method sppm gives Method::Sppm");
    };
    let result = render::sppm::render_sppm(&gpu, scene, &options, sppm, &mut observer);
    let out = observer.finish_with(result, outputs.images(), &provenance)?;
    provenance.iterations = Some(out.iterations);
    provenance.photons_emitted = Some(out.photons_emitted);
    let written = write_images(&out.image, outputs.images(), &provenance)?;
    if args.json {
        crate::cli::print_json(&Report {
            provenance: &provenance,
            outputs: written.clone(),
            figures: serde_json::json!({
                "method": "sppm",
                "sppm": sppm,
                "iterations": out.iterations,
                "stopped_by": out.stopped_by,
                "photons_emitted": out.photons_emitted,
                "initial_radius": out.initial_radius,
                "final_largest_radius": out.final_largest_radius,
                "adaptive_pilot": out.adaptive.as_ref().map(|a| a.0),
                "adaptive_samples": out.adaptive.as_ref().map(|a| &a.1),
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
            "SPPM: {} iterations in {:.1} s (stopped by {}), {} photons emitted, radius {} -> {:.5} (largest)",
            out.iterations,
            out.timings.wall_seconds,
            match out.stopped_by {
                StopReason::Iterations => "its iterations",
                StopReason::Time => "--time",
            },
            out.photons_emitted,
            out.initial_radius,
            out.final_largest_radius
        );
        if let Some((pilot, s)) = &out.adaptive {
            let pixels = (options.width * options.height) as u64;
            eprintln!(
                "adaptive sampling: after a pilot of {pilot} iterations, the photon half is interpolated at {} of {pixels} pixels and gathered at the other {} ({:.1}%)",
                s.interpolated,
                pixels - s.interpolated,
                100.0 * (pixels - s.interpolated) as f64 / pixels as f64
            );
        }
        for (p, _) in &written {
            eprintln!("wrote {p}");
        }
    }
    Ok(())
}
