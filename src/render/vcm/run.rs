//! A VCM render from start to finish, through the progressive loop that
//! SPPM shares (`render::progressive`).

use crate::gpu::Result;
use crate::image::Image;
use crate::render::explain::ExplainLine;
use crate::render::observer::{RenderObserver, StopReason};
use crate::render::options::RenderOptions;
use crate::render::progressive::{run_progressive, Progressed, Progressive};
use crate::scene::Scene;
use crate::timing::Timings;

use super::options::VcmOptions;
use super::Vcm;

/// What a VCM render did.
pub struct VcmOutput {
    pub image: Image,
    pub stopped_by: StopReason,
    pub timings: Timings,
    pub iterations: u32,
    /// Light paths traced in all.
    pub light_paths: u64,
    pub initial_radius: f32,
    pub final_radius: f32,
    pub explain: Vec<ExplainLine>,
    /// With `technique_images` asked: what each technique carried, in the order
    /// of `TECHNIQUES` (cut to the crop as the image is), which sums to the
    /// image; otherwise none.
    pub techniques: Vec<Image>,
}

/// Renders `scene` by vertex connection and merging: iterations until
/// `vcm.iterations` or `vcm.seconds`, whichever comes first. With
/// `technique_images`, also reads back what each technique carried.
pub fn render_vcm(
    gpu: &crate::gpu::Gpu,
    scene: &Scene,
    options: &RenderOptions,
    vcm: &VcmOptions,
    technique_images: bool,
    observer: &mut dyn RenderObserver,
) -> Result<VcmOutput> {
    options.check_pixel_bounds()?;
    options.check_materials(scene)?;
    let mut run = Vcm::new(gpu, scene, options, vcm)?;
    let Progressed {
        image,
        stopped_by,
        timings,
    } = run_progressive(&mut run, options, (vcm.iterations, vcm.seconds), observer)?;
    let iterations = run.iteration;
    let light_paths = if vcm.mode.traces_light_paths() {
        iterations as u64 * vcm.light_paths as u64
    } else {
        0
    };
    let techniques = if technique_images {
        let images = run.technique_images()?;
        images.into_iter().map(|t| options.cut(t)).collect()
    } else {
        Vec::new()
    };
    Ok(VcmOutput {
        techniques,
        explain: explain(&run, options),
        image,
        stopped_by,
        timings,
        iterations,
        light_paths,
        initial_radius: run.initial_radius,
        final_radius: run.radius(iterations.max(1)),
    })
}

impl Progressive for Vcm {
    fn iterations_done(&self) -> u32 {
        self.iteration
    }

    fn iterate(&mut self, timings: &mut Timings, _observer: &mut dyn RenderObserver) -> Result<()> {
        Vcm::iterate(self, timings)
    }

    fn image(&self) -> Result<Image> {
        Vcm::image(self)
    }
}

/// What each stage did and why, for `--explain`.
fn explain(run: &Vcm, options: &RenderOptions) -> Vec<ExplainLine> {
    let o = &run.options;
    let mode = o.mode;
    let line = |stage: &str, ran: bool, why: String| ExplainLine {
        stage: stage.into(),
        passes: run.iteration as usize,
        ran,
        why,
    };
    let mut out = vec![
        line(
            "light paths",
            mode.traces_light_paths(),
            if mode.traces_light_paths() {
                format!(
                    "{} light paths an iteration, traced as photons are, every diffuse hit stored as a light vertex with its MIS partials beside it; up to {} segments a path",
                    o.light_paths, o.max_segments
                )
            } else {
                "path tracing needs no light vertices".into()
            },
        ),
        line(
            "light tracing",
            mode.splats(),
            if mode.splats() {
                "every light vertex of the map connected to the camera in a fragment pass, then drawn as a point where it projects, added into the light image".into()
            } else {
                format!("--vcm-mode {} connects no light vertex to the camera", mode.name())
            },
        ),
        line(
            "merging",
            mode.merges(),
            if mode.merges() {
                format!(
                    "a map of the light vertices each iteration (counting sort), radius {:.4} at the first iteration shrinking as i^({:.3})",
                    run.initial_radius,
                    (o.alpha - 1.0) * 0.5
                )
            } else if mode.traces_light_paths() {
                format!(
                    "--vcm-mode {} merges nothing; the light vertices are still compacted each iteration (counting sort, one cell) for light tracing and connections to walk",
                    mode.name()
                )
            } else {
                format!("--vcm-mode {} merges nothing", mode.name())
            },
        ),
        line(
            "camera paths",
            true,
            format!(
                "one path a pixel through mirrors and glass and on past diffuse vertices by Russian roulette ({}); at each diffuse vertex: {}",
                if mode.connects() {
                    format!(
                        "{} of the light paths' continuation probability",
                        o.camera_continuation
                    )
                } else {
                    "the light paths' continuation probability".into()
                },
                match mode {
                    crate::render::vcm::VcmMode::Pt => "next-event estimation, weighted against paths that hit a light",
                    crate::render::vcm::VcmMode::Lt => "nothing (light tracing draws what the camera sees of diffuse surfaces; lights seen directly or through mirrors and glass are the camera path's)",
                    crate::render::vcm::VcmMode::Ppm => "merging at the first, unweighted, and the path ends",
                    crate::render::vcm::VcmMode::Bpt => "next-event estimation and --connections connections to light vertices drawn from all of the iteration's, each weighted by the balance heuristic",
                    crate::render::vcm::VcmMode::Vcm => "next-event estimation, --connections connections to light vertices drawn from all of the iteration's, and merging, each weighted by the balance heuristic",
                }
            ),
        ),
    ];
    if let Some(b) = options.pixel_bounds {
        out.insert(
            0,
            ExplainLine {
                stage: "crop".into(),
                passes: 0,
                ran: true,
                why: format!(
                    "pixels {}..{} x {}..{} of the {} x {} frame: every iteration runs over the whole frame (light tracing lands anywhere in it) and the crop is cut from it",
                    b.x0, b.x1, b.y0, b.y1, options.width, options.height
                ),
            },
        );
    }
    out
}
