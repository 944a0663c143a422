//! Radiosity through a render: the caustic map and the solution, made once,
//! then each eye sample's lookup at its first hits, or its final gather.

use crate::gpu::Result;
use crate::image::Image;
use crate::timing::Timings;

use super::{Radiosity, RadiosityOptions, RadiosityReport, SolutionGather};
use crate::render::observer::{Progress, RenderObserver};
use crate::render::photon_map::MapEstimate;
use crate::render::photon_options::WithCausticMap;
use crate::render::sample::{FrameMethod, Prepare, SampleFrame};

/// The caustic map, the solution's atlas and passes, its report, and the
/// final gather's rays where it gathers.
pub struct RadiosityRun {
    pub caustics: Option<MapEstimate>,
    pub radiosity: Radiosity,
    pub report: RadiosityReport,
    pub gather: Option<SolutionGather>,
}

impl RadiosityRun {
    /// The caustic map, then the solution to convergence or its shot limit.
    pub fn prepare(
        p: &Prepare<'_>,
        with: &WithCausticMap<RadiosityOptions>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let o = &with.method;
        let found =
            MapEstimate::caustics_with_records(p, with, o.caustic_map(), timings, observer)?;
        let (caustics, records) = found.unzip();
        let mut radiosity = Radiosity::new(p.gpu, p.scene, p.width, p.height, o)?;
        if let Some(records) = records.filter(|_| o.shoot_caustics) {
            let t0 = std::time::Instant::now();
            radiosity.deposit(p.textures, &records)?;
            timings.add_since("caustic deposit", 0.0, t0, 1);
        }
        let report = radiosity.solve(p.scene, p.textures, timings, &mut |_shot, unshot| {
            observer.progress(&Progress::stage(
                "radiosity",
                ((1.0 - unshot) * 1000.0) as u64,
                1000,
            ));
        })?;
        let gather = match o.gather_rays {
            0 => None,
            rays => Some(SolutionGather::new(p.gpu, p.width, p.height, rays)?),
        };
        Ok(Self {
            caustics,
            radiosity,
            report,
            gather,
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
        let at = f.at;
        self.radiosity.run(
            f.textures,
            f.direct,
            self.gather.as_ref(),
            f.seed,
            timings,
            &mut |done, total| {
                observer.progress(&Progress::at(
                    "radiosity gather",
                    done as u64,
                    total as u64,
                    at,
                ))
            },
        )?;
        image.add(&self.radiosity.read_indirect());
        Ok(image)
    }
}
