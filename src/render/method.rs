//! One arm per frame method: what `Method`'s options become once the
//! method is prepared, and what it leaves behind after the last sample. To
//! add a method, write its module (options, a run type with `prepare`, and
//! `FrameMethod`), then one arm here and one in `Method`; the compiler lists
//! every match still to extend.

use crate::error::Error;
use crate::gpu::{Gpu, Result};
use crate::image::Image;
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

use super::differentials::DifferentialsRun;
use super::igi::IgiRun;
use super::observer::RenderObserver;
use super::options::{Method, RenderOptions};
use super::photon_map::PhotonMapRun;
use super::radiosity::RadiosityRun;
use super::sample::{FrameMethod, Prepare, SampleFrame};

/// A frame method's state: its maps, textures and per-sample reports.
// One a render, moved rarely: the variants' sizes do not matter.
#[allow(clippy::large_enum_variant)]
pub enum MethodRun {
    DirectOnly,
    PhotonMap(PhotonMapRun),
    Igi(IgiRun),
    Differentials(DifferentialsRun),
    Radiosity(RadiosityRun),
}

impl MethodRun {
    /// Prepares `options.method` before the first eye sample: photons,
    /// maps, VPLs, the radiosity solution.
    pub fn prepare(
        gpu: &Gpu,
        scene: &Scene,
        textures: &SceneTextures,
        options: &RenderOptions,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let p = Prepare {
            gpu,
            scene,
            textures,
            width: options.width,
            height: options.height,
            seed: options.seed,
        };
        let (t, obs) = (timings, observer);
        Ok(match &options.method {
            Method::DirectOnly => MethodRun::DirectOnly,
            Method::PhotonMap(o) => MethodRun::PhotonMap(PhotonMapRun::prepare(&p, o, t, obs)?),
            Method::Igi(o) => MethodRun::Igi(IgiRun::prepare(&p, o, t, obs)?),
            Method::Differentials(o) => {
                MethodRun::Differentials(DifferentialsRun::prepare(&p, o, t, obs)?)
            }
            Method::Radiosity(o) => MethodRun::Radiosity(RadiosityRun::prepare(&p, o, t, obs)?),
            Method::Sppm(_) => return Err(Error::InvalidOption(
                "SPPM is progressive, not a frame method: render it with render::sppm::render_sppm"
                    .into(),
            )),
            Method::Vcm(_) => return Err(Error::InvalidOption(
                "VCM is progressive, not a frame method: render it with render::vcm::render_vcm"
                    .into(),
            )),
        })
    }

    fn frame_method(&mut self) -> Option<&mut dyn FrameMethod> {
        match self {
            MethodRun::DirectOnly => None,
            MethodRun::PhotonMap(m) => Some(m),
            MethodRun::Igi(m) => Some(m),
            MethodRun::Differentials(m) => Some(m),
            MethodRun::Radiosity(m) => Some(m),
        }
    }

    /// How far beyond a crop the eye passes must draw, in pixels, for the
    /// crop's pixels to be the frame's: 0 where no pixel's light reads
    /// another's, the reach of the reads where they are local (tested: a crop
    /// then equals the frame's pixels bit for bit). None: the eye passes run
    /// over the whole frame and the crop is cut from it.
    pub fn crop_margin(&self) -> Option<u32> {
        match self {
            // Adaptive sampling plans from neighbouring pixels and compacts
            // the pixels it computes; differentials' gather was measured to
            // differ at a crop's pixels when the others are not drawn.
            MethodRun::PhotonMap(m) => m.pyramid.is_none().then_some(0),
            MethodRun::Differentials(_) => None,
            MethodRun::Igi(m) => Some(m.gather.as_ref().map_or(0, |g| g.igi.neighbour_reach())),
            MethodRun::DirectOnly | MethodRun::Radiosity(_) => Some(0),
        }
    }

    /// One eye sample's image.
    pub fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        match self.frame_method() {
            None => Ok(f.direct.read_radiance()),
            Some(m) => m.sample(f, timings, observer),
        }
    }
}
