//! Radiosity through a render: the caustic map and the solution, made once,
//! then each eye sample's lookup at its first hits.

use crate::gpu::{Gpu, Result};
use crate::image::Image;
use crate::photon::PhotonConfig;
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

use super::{Radiosity, RadiosityOptions, RadiosityReport};
use crate::render::observer::{Progress, RenderObserver};
use crate::render::photon_map::MapEstimate;
use crate::render::radiance_estimate::EstimateOptions;
use crate::render::sample::{FrameMethod, SampleFrame};

/// The caustic map, the solution's atlas and passes, and its report.
pub struct RadiosityRun {
    pub caustics: Option<MapEstimate>,
    pub radiosity: Radiosity,
    pub report: RadiosityReport,
}

impl RadiosityRun {
    /// The caustic map, then the solution to convergence or its shot limit.
    pub fn prepare(
        gpu: &Gpu,
        f: (&Scene, &SceneTextures),
        (photons, estimate, o): (&PhotonConfig, &EstimateOptions, &RadiosityOptions),
        (w, h, seed): (u32, u32, u32),
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let (scene, textures) = f;
        observer.progress(&Progress::stage("photons", 0, 1));
        let caustics = MapEstimate::caustics(gpu, f, (photons, estimate), (w, h, seed), timings)?;
        let mut radiosity = Radiosity::new(gpu, scene, w, h, o)?;
        let report = radiosity.solve(scene, textures, timings, &mut |_shot, unshot| {
            observer.progress(&Progress::stage(
                "radiosity",
                ((1.0 - unshot) * 1000.0) as u64,
                1000,
            ));
        })?;
        Ok(Self {
            caustics,
            radiosity,
            report,
        })
    }
}

impl FrameMethod for RadiosityRun {
    /// The caustic estimate with the direct light, plus the solution's light.
    fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        let mut image = MapEstimate::image_or_direct(self.caustics.as_mut(), f, timings, observer)?;
        self.radiosity.run(f.textures, f.direct, timings)?;
        image.add(&self.radiosity.read_indirect());
        Ok(image)
    }
}
