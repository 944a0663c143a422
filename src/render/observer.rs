//! What a render tells its caller while it runs: progress, every pass of the
//! radiance estimate (with the running image on request: snapshots), and each
//! finished view. The library writes no files; observers the CLI supplies do.

use crate::gpu::Result;
use crate::image::Image;

/// Where in the frame a pass is: view and eye sample.
#[derive(Clone, Copy, Debug)]
pub struct At {
    pub view: usize,
    pub views: usize,
    pub sample: u32,
    pub samples: u32,
}

/// Progress of one stage: `done` of `total` units, at a view and eye sample.
#[derive(Clone, Copy, Debug)]
pub struct Progress<'a> {
    pub stage: &'a str,
    pub done: u64,
    pub total: u64,
    /// None for work done once per render (photons).
    pub at: Option<At>,
}

impl<'a> Progress<'a> {
    pub fn stage(stage: &'a str, done: u64, total: u64) -> Self {
        Self {
            stage,
            done,
            total,
            at: None,
        }
    }

    pub fn at(stage: &'a str, done: u64, total: u64, at: At) -> Self {
        Self {
            stage,
            done,
            total,
            at: Some(at),
        }
    }
}

/// A pass of the radiance estimate, or (with `finished`) its final state.
pub struct EstimatePass<'a> {
    pub at: At,
    pub pass: u32,
    /// Pixels still searching after this pass.
    pub searching: u64,
    /// Pixels with a diffuse hit, which take part.
    pub query_pixels: u64,
    /// Seconds of estimate so far, observers' own time not counted.
    pub seconds: f64,
    pub finished: bool,
    /// A progressive render's last pass: what ended it.
    pub stopped_by: Option<StopReason>,
    pub(super) image: &'a dyn Fn() -> Result<Image>,
}

/// What ended a progressive render.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopReason {
    /// It ran the iterations asked for.
    Iterations,
    /// Its time (`--time`) was up.
    Time,
}

impl EstimatePass<'_> {
    /// The image of the estimate as it stands (composed on the GPU, read back).
    pub fn image(&self) -> Result<Image> {
        (self.image)()
    }
}

/// Hears about a render as it runs. Every method does nothing by default;
/// `()` is the observer that wants nothing.
pub trait RenderObserver {
    fn progress(&mut self, _progress: &Progress<'_>) {}

    /// After every pass of every radiance estimate, and once more when it has
    /// finished. An error stops the render.
    fn estimate_pass(&mut self, _pass: &EstimatePass<'_>) -> Result<()> {
        Ok(())
    }

    /// After each eye sample of a view: `done` samples so far, and their
    /// mean on demand (what a render stopped now would have made).
    fn samples_done(&mut self, _view: usize, _done: u32, _mean: &dyn Fn() -> Image) {}

    /// A view's finished image (the mean of its eye samples).
    fn frame(&mut self, _view: usize, _image: &Image) -> Result<()> {
        Ok(())
    }
}

impl RenderObserver for () {}
