//! What the frame hands a method for each eye sample, and the trait every
//! frame method implements: made once before the first sample (its
//! constructor: photons, VPLs, elements), then asked for each eye sample's
//! image at that sample's first hits.

use crate::gpu::{Gpu, Result};
use crate::image::Image;
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

use super::direct::DirectLight;
use super::observer::{At, RenderObserver};

/// What a method is prepared with: the GPU, the scene and its textures,
/// the image's size and the render's seed.
#[derive(Clone, Copy)]
pub struct Prepare<'a> {
    pub gpu: &'a Gpu,
    pub scene: &'a Scene,
    pub textures: &'a SceneTextures,
    pub width: u32,
    pub height: u32,
    pub seed: u32,
}

/// One eye sample's first hits, ready for the method.
#[derive(Clone, Copy)]
pub struct SampleFrame<'a> {
    pub scene: &'a Scene,
    /// The eye (IGI's discontinuity buffer measures depth from it).
    pub camera_position: glam::Vec3,
    pub textures: &'a SceneTextures,
    pub direct: &'a DirectLight,
    pub seed: u32,
    pub at: At,
}

/// A method that runs inside the frame, once per eye sample.
pub trait FrameMethod {
    /// The sample's image: its direct light and specular paths (in
    /// `f.direct`) plus the method's light at its first hits.
    fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image>;
}
