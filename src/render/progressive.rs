//! Progressive methods: each iteration refines one image, and the image
//! converges as iterations run. SPPM (`render::sppm`) and VCM
//! (`render::vcm`) implement `Progressive`, as the frame methods implement
//! `FrameMethod`; `run_progressive` drives either until its iterations or
//! its time run out, telling the observer of each iteration (snapshots, the
//! live image, `--on-signal`) and of the final image.

use crate::gpu::Result;
use crate::image::Image;
use crate::render::observer::{At, EstimatePass, Progress, RenderObserver, StopReason};
use crate::render::options::RenderOptions;
use crate::timing::Timings;

/// The progress stage every progressive method reports its iterations as.
pub const ITERATIONS_STAGE: &str = "progressive iterations";

pub trait Progressive {
    /// Iterations run so far.
    fn iterations_done(&self) -> u32;
    /// Runs one more iteration.
    fn iterate(&mut self, timings: &mut Timings, observer: &mut dyn RenderObserver) -> Result<()>;
    /// The image of the iterations run (the whole frame).
    fn image(&self) -> Result<Image>;
}

/// What `run_progressive` did: the final image (cut to the crop), why it
/// stopped, and the timings (wall time included).
pub struct Progressed {
    pub image: Image,
    pub stopped_by: StopReason,
    pub timings: Timings,
}

/// Runs `method` until `iterations` are done or, after at least one, until
/// `seconds` of its own time (the observer's excluded) have passed.
pub fn run_progressive(
    method: &mut dyn Progressive,
    options: &RenderOptions,
    (iterations, seconds): (u32, Option<f64>),
    observer: &mut dyn RenderObserver,
) -> Result<Progressed> {
    let mut timings = Timings::default();
    let wall = std::time::Instant::now();
    let mut observed = 0.0;
    let mut stopped_by = StopReason::Iterations;
    let at = At {
        view: 0,
        views: 1,
        sample: 0,
        samples: 1,
    };
    while method.iterations_done() < iterations {
        crate::interrupt::check()?;
        let elapsed = wall.elapsed().as_secs_f64() - observed;
        if seconds.is_some_and(|s| method.iterations_done() > 0 && elapsed >= s) {
            stopped_by = StopReason::Time;
            break;
        }
        method.iterate(&mut timings, observer)?;
        let t0 = std::time::Instant::now();
        let done = method.iterations_done();
        observer.progress(&Progress::stage(
            ITERATIONS_STAGE,
            done as u64,
            iterations as u64,
        ));
        let image = || Ok(options.cut(method.image()?));
        observer.estimate_pass(&EstimatePass {
            stopped_by: None,
            at,
            pass: done - 1,
            searching: 0,
            query_pixels: 0,
            seconds: wall.elapsed().as_secs_f64() - observed,
            finished: false,
            image: &image,
        })?;
        observed += t0.elapsed().as_secs_f64();
    }
    let image = options.cut(method.image()?);
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    observer.estimate_pass(&EstimatePass {
        at,
        pass: method.iterations_done(),
        searching: 0,
        query_pixels: 0,
        seconds: timings.wall_seconds - observed,
        finished: true,
        stopped_by: Some(stopped_by),
        image: &|| Ok(image.clone()),
    })?;
    observer.frame(0, &image)?;
    Ok(Progressed {
        image,
        stopped_by,
        timings,
    })
}
