//! A frame render (`--method paper`, `igi`, `differentials`, `radiosity`):
//! one or more views on one prepared method, and its summary.

use anyhow::Result;
use photonmap::render::radiance_estimate::LeakTest;

use photonmap::gpu::Platform;
use photonmap::render::{self, PassPlan, RenderOptions};

use super::args::{Format, RenderArgs, Start};
use super::observer::CliObserver;
use super::output::{print_explain, provenance, write_images, write_software_reference, Report};
use crate::cli::args::Method;
use crate::cli::progress::Work;

pub(super) fn run(args: &RenderArgs, platform: Platform) -> Result<()> {
    let Start {
        outputs,
        loaded,
        options,
    } = args.start()?;
    let scene = &loaded.scene;
    let cameras = match &args.camera_path {
        Some(p) => photonmap::scene::camera_path::load_camera_path(p, &scene.camera, scene.origin)?,
        None => vec![scene.camera.clone()],
    };
    let gpu = crate::cli::gpu(platform)?;
    let method = match (args.method, args.final_gather.is_some()) {
        (Method::Igi, _) => "igi",
        (Method::Differentials, _) => "differentials",
        (Method::Radiosity, _) => "radiosity",
        (_, true) => "final-gather",
        _ => "paper",
    };
    let mut provenance = provenance(loaded.provenance, &gpu, method, &options);
    let work = Work::Paper {
        passes: PassPlan::new(scene, &options).passes_per_sample(),
        samples: options.spp,
        views: cameras.len(),
        direct_only: args.direct_only,
    };
    let mut observer = CliObserver::new(args, scene, &outputs, work, &provenance);
    let result = render::render_views(&gpu, scene, &options, &cameras, &mut observer);
    let out = observer.finish_with(result, outputs.images(), &provenance)?;
    provenance.photons_emitted = out
        .photons()
        .map(|p| p.trace.photons_used)
        .or(out.differentials().map(|d| d.trace.photons_used))
        .map(u64::from);
    let written = write_images(&out.image, outputs.images(), &provenance)?;
    if let Some(path) = &args.reference_software {
        let leak = options.method.estimate().map(|e| e.leak);
        if !args.quiet && leak.is_some_and(|l| l != LeakTest::None) {
            eprintln!("note: the software reference is the paper's estimate, with no leak test; add --leak-test none to compare like with like");
        }
        write_software_reference(&out, scene, path, args.quiet)?;
    }
    if args.json {
        let photon_map = options.method.photon_map();
        let igi = match &options.method {
            render::Method::Igi(o) => Some(&o.method),
            _ => None,
        };
        crate::cli::print_json(&Report {
            provenance: &provenance,
            outputs: written.clone(),
            figures: serde_json::json!({
                "method": method,
                "timings": out.timings,
                "estimates": out.estimates(),
                "final_gather": photon_map.and_then(|o| o.final_gather.clone()),
                "gathers": out.gathers(),
                "adaptive": photon_map.and_then(|o| o.adaptive.clone()),
                "adaptive_samples": out.adaptive(),
                "igi": igi,
                "vpls": out.vpls(),
                "igi_samples": out.igi(),
                "bias_compensation_samples": out.igi_run().and_then(|r| r.compensation.as_ref()).map(|c| &c.stats),
                "differentials": out.differentials(),
                "footprint_samples": out.footprint_estimates(),
                "radiosity": out.radiosity(),
            }),
        })?;
    }
    if args.explain {
        print_explain(&out.explain(scene, &options));
    }
    if !args.quiet {
        print_summary(&out, &options, &written);
    }
    Ok(())
}

pub(super) fn print_summary(
    out: &render::RenderOutput,
    options: &RenderOptions,
    written: &[(String, Format)],
) {
    eprint!("{}", out.timings.table());
    if !out.estimates().is_empty() {
        let passes: u32 = out.estimates().iter().map(|e| e.passes).sum();
        let draws: u64 = out.estimates().iter().map(|e| e.tile_draws).sum();
        let e = &out.estimates()[0];
        eprintln!(
            "radiance estimate: {passes} passes in {} run{}, {} of {} pixels searched, {draws} tile draws of {} tiles",
            out.estimates().len(),
            if out.estimates().len() == 1 { "" } else { "s" },
            e.query_pixels,
            options.width as u64 * options.height as u64,
            e.tiles
        );
    }
    if let Some(g) = out.gathers().first() {
        // Totals over every eye sample (and, adaptive, every level).
        let passes: u32 = out.gathers().iter().map(|g| g.estimate_passes).sum();
        let batches: u32 = out.gathers().iter().map(|g| g.batches).sum();
        let hits: u64 = out.gathers().iter().map(|g| g.queries).sum();
        eprintln!(
            "final gather: {} rays a pixel; {batches} batches, {hits} gather rays reached a diffuse surface, {passes} estimate passes in all",
            g.rays_per_pixel,
        );
    }
    if let (Some(v), Some(s)) = (out.vpls(), out.igi().first()) {
        eprintln!(
            "IGI: {} VPLs from {} light paths (bounding distance {}); {:.1} VPL shadow rays at each of {} shading points; caustics {}",
            v.vpls,
            v.paths,
            v.min_distance,
            s.vpls_per_point,
            s.shading_points,
            if out.photons().is_some() {
                "from the caustic photon map"
            } else {
                "none (nothing specular in the scene)"
            }
        );
    }
    if let Some(c) = out.igi_run().and_then(|r| r.compensation.as_ref()) {
        let hits: u64 = c.stats.iter().map(|s| s.queries).sum();
        eprintln!(
            "IGI bias compensation: {} rays a pixel, {hits} met a diffuse surface nearer than 1.2 x {} (global map of {} photons, k = {})",
            c.rays(),
            c.fade(),
            c.photons_stored,
            c.k()
        );
    }
    if let Some(line) = radiosity_summary(out) {
        eprintln!("{line}");
    }
    if let (Some(d), Some(s)) = (out.differentials(), out.footprint_estimates().first()) {
        let pilot = d.pilot_mean_diffuse_footprints.map_or(String::new(), |m| {
            format!(" (auto: {m:.4} diffuse footprints a hit at s = 1 in the pilot)")
        });
        eprintln!(
            "photon differentials: {} footprints ({} diffuse, {} caustic, {} degenerate); s = {:.2}{pilot}, caustics {}, r_max {}, {} coverage probes a footprint, {} footprints; BVH of {} leaves of {} (auto {}); {:.1} footprints hold a first hit on average (k_PD), {:.1} nodes and {:.1} footprints examined, {} passes",
            d.footprints,
            d.diffuse_footprints,
            d.footprints - d.diffuse_footprints,
            d.degenerate_footprints,
            d.smoothing,
            d.caustic_smoothing,
            d.max_radius,
            d.coverage_samples,
            clap::ValueEnum::to_possible_value(&d.footprint_shape)
                .map_or_else(String::new, |v| v.get_name().to_string()),
            d.leaves,
            d.leaf_size,
            d.auto_leaf_size,
            s.mean_footprints,
            s.mean_nodes,
            s.mean_examined,
            s.passes,
        );
    }
    if !out.adaptive().is_empty() {
        let computed: u64 = out.adaptive().iter().map(|a| a.computed).sum();
        let all: u64 = out.adaptive().iter().map(|a| a.pixels_with_hits).sum();
        let levels: Vec<String> = out.adaptive()[0]
            .levels
            .iter()
            .map(|(s, c, i)| format!("stride {s}: {c} computed, {i} interpolated"))
            .collect();
        eprintln!(
            "adaptive sampling: global light computed at {computed} of {all} pixels with a diffuse hit ({:.1}%); {}",
            100.0 * computed as f64 / all.max(1) as f64,
            levels.join("; ")
        );
    }
    for (p, _) in written {
        eprintln!("wrote {p}");
    }
}

/// The stderr line on a radiosity solution, where the method made one.
fn radiosity_summary(out: &render::RenderOutput) -> Option<String> {
    let r = out.radiosity()?;
    Some(format!(
        "radiosity: {} patches in {} tiles of {} x {} ({} splits{}), {} elements; {} shots in {:.2} s, {}: {:.2}% of the power unshot; caustics {}; {}",
        r.patches,
        r.tiles,
        r.element_resolution,
        r.element_resolution,
        r.splits,
        if r.atlas_full { ", the atlas full" } else { "" },
        r.elements,
        r.shots,
        r.seconds,
        if r.converged { "converged" } else { "stopped at --max-shots" },
        100.0 * r.unshot_fraction,
        if out.photons().is_some() {
            "from the caustic photon map"
        } else {
            "none (nothing specular in the scene)"
        },
        match out.radiosity_run().and_then(|run| run.gather.as_ref()) {
            Some(g) => format!(
                "final gather of {} rays a pixel, direct light at their hits by shadow rays",
                g.rays_per_pixel()
            ),
            None => "the solution read at each pixel".to_string(),
        }
    ))
}
