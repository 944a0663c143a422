//! An SPPM render from start to finish: iterations until their number or
//! the time runs out, the observer told of each, and the `--explain` lines.

use crate::gpu::{Gpu, Result};
use crate::image::Image;
use crate::render::adaptive::AdaptiveStats;
use crate::render::explain::ExplainLine;
use crate::render::observer::{RenderObserver, StopReason};
use crate::render::options::RenderOptions;
use crate::render::progressive::{run_progressive, Progressed, Progressive};
use crate::scene::Scene;
use crate::timing::Timings;

use super::options::{DirectLighting, SppmOptions};
use super::Sppm;

/// What a progressive render did.
pub struct SppmOutput {
    pub image: Image,
    /// Whether the iterations or the time ran out.
    pub stopped_by: StopReason,
    pub timings: Timings,
    pub iterations: u32,
    pub photons_emitted: u64,
    pub initial_radius: f32,
    /// The largest radius among pixels that gathered photons, at the end.
    pub final_largest_radius: f32,
    pub explain: Vec<ExplainLine>,
    /// Adaptive sampling: the pilot's length and the plan's counts (None
    /// when not adaptive, or stopped before the plan).
    pub adaptive: Option<(u32, AdaptiveStats)>,
}

/// Renders `scene` by SPPM: iterations until `sppm.iterations` or
/// `sppm.seconds`, whichever comes first. The observer sees each iteration as
/// an estimate pass (snapshots), and the final image.
pub fn render_sppm(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    sppm: &SppmOptions,
    observer: &mut dyn RenderObserver,
) -> Result<SppmOutput> {
    // A crop renders the whole frame and keeps its pixels: each iteration's
    // grid follows the largest radius over every pixel.
    options.check_pixel_bounds()?;
    options.check_materials(scene)?;
    let mut run = Sppm::new(gpu, scene, options, sppm)?;
    let Progressed {
        image,
        stopped_by,
        timings,
    } = run_progressive(&mut run, options, (sppm.iterations, sppm.seconds), observer)?;
    let final_largest_radius = run.largest_radius()?;
    let mut explain = explain(&run, sppm);
    if let Some(b) = options.pixel_bounds {
        explain.insert(
            0,
            ExplainLine {
                stage: "crop".into(),
                passes: 0,
                ran: true,
                why: format!(
                    "pixels {}..{} x {}..{} of the {} x {} frame: every iteration runs over the whole frame (its grid follows the largest radius over every pixel) and the crop is cut from it",
                    b.x0, b.x1, b.y0, b.y1, options.width, options.height
                ),
            },
        );
    }
    let adaptive = run
        .adaptive_stats()
        .map(|s| (run.adaptive.as_ref().expect("adaptive").pilot, s.clone()));
    Ok(SppmOutput {
        stopped_by,
        adaptive,
        image,
        timings,
        iterations: run.iteration,
        photons_emitted: run.iteration as u64 * sppm.photons_per_iteration as u64,
        initial_radius: run.initial_radius,
        final_largest_radius,
        explain,
    })
}

fn explain(run: &Sppm, o: &SppmOptions) -> Vec<ExplainLine> {
    let line = |stage: &str, passes: usize, why: String| ExplainLine {
        stage: stage.into(),
        passes,
        ran: true,
        why,
    };
    let i = run.iteration as usize;
    let s = &run.scene;
    let mut lines = vec![
        line(
            "eye paths",
            i * run.plan.passes_per_sample() as usize,
            format!(
                "one jittered eye path per pixel per iteration, {} specular depths, {}",
                run.plan.depths,
                match o.direct {
                    DirectLighting::ShadowRays => format!(
                        "{} shadow ray(s) per area light at the visible point",
                        o.shadow_rays.max(1)
                    ),
                    DirectLighting::Photons => "no shadow rays: photons carry direct light".into(),
                }
            ),
        ),
        line(
            "trace photons",
            i * (s.photon_map.max_bounces as usize + 1),
            format!(
                "{} photons emitted per iteration, {} bounces, every frame traced (no read-back), stored from their {} hit",
                o.photons_per_iteration,
                s.photon_map.max_bounces,
                if s.photon_map.store_direct { "first" } else { "second" }
            ),
        ),
    ];
    if s.photon_map.caustics_only {
        lines.push(line(
            "caustics only",
            0,
            "the scene stores caustic photons only (caustics_only = true): SPPM converges to direct light plus caustics, which is the whole image only where, as in RING, no light reaches a diffuse surface by another diffuse one".into(),
        ));
    }
    if let Some(g) = &run.grid {
        lines.push(line(
            "build map",
            i,
            format!(
                "every iteration, over the whole scene: {} x {} x {} cells of about {:.4} (the largest radius that has gathered photons, read back after iterations 1, 2, 4, ... and every 64th)",
                g.resolution[0], g.resolution[1], g.resolution[2], run.cell
            ),
        ));
    }
    if let Some(a) = &run.adaptive {
        lines.push(match (&a.planned, run.adaptive_stats()) {
            (Some(p), Some(s)) => line(
                "adaptive plan",
                12,
                format!(
                    "after a pilot of {} iterations at every pixel, the pyramid (strides 8, 4, 2, 1, threshold {}) on the pilot's photon half: {} pixels interpolated, {} go on gathering ({:.1}% of the image), packed into {} rows",
                    a.pilot,
                    a.options.threshold,
                    s.interpolated,
                    p.computed.len(),
                    100.0 * p.computed.len() as f64 / (run.image.width * run.image.height) as f64,
                    p.rows
                ),
            ),
            _ => ExplainLine {
                stage: "adaptive plan".into(),
                passes: 0,
                ran: false,
                why: format!("the render stopped within its pilot of {} iterations", a.pilot),
            },
        });
    }
    lines.push(line(
        "gather + update",
        i,
        format!(
            "each pixel gathers photons arriving on its visible side within its own radius (first {}, alpha {}), in one pass, in place",
            run.initial_radius, o.alpha
        ),
    ));
    lines
}

impl Progressive for Sppm {
    fn iterations_done(&self) -> u32 {
        self.iteration
    }

    fn iterate(&mut self, timings: &mut Timings, observer: &mut dyn RenderObserver) -> Result<()> {
        Sppm::iterate(self, timings, observer)
    }

    fn image(&self) -> Result<Image> {
        Sppm::image(self)
    }
}
