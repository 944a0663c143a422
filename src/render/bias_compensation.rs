//! Bias compensation for IGI's bounded geometry term (Kollig and Keller):
//! the light the bound f(0.8 m, 1.2 m, d) leaves out of a VPL's connection,
//! (1 - f(d)) of it, where two diffuse surfaces are closer than 1.2 m, in
//! corners and under objects.
//!
//! At each pixel's first diffuse hit x, cosine-distributed gather rays find
//! the diffuse surface y seen straight from x; a ray weighs what y sends back
//! by 1 - f(|y - x|), and gives nothing beyond 1.2 m, where the VPLs carry
//! the whole connection. Kollig and Keller evaluate the light leaving y by
//! recursing into IGI; here a global photon map of every diffuse hit, direct
//! ones included, estimates it, as final gather's does: the residual is
//! short-range, so the map's own blur enters only its share. The rays are
//! final gather's passes (`gather_rays.frag` with `u_fade_distance` = m), so
//! the compensation is a final gather restricted to what the bound removes.

use crate::gpu::Result;
use crate::photon::{self, PhotonConfig, PhotonMap};

use super::final_gather::{self, FinalGather, FinalGatherOptions, GatherStats};
use super::observer::{Progress, RenderObserver};
use super::radiance_estimate::EstimateOptions;
use super::sample::{Prepare, SampleFrame};
use super::{Image, Timings};

/// The compensation's global map and gather textures, and each eye sample's
/// gather.
pub struct BiasCompensation {
    pub map: PhotonMap,
    pub gather: FinalGather,
    options: FinalGatherOptions,
    estimate: EstimateOptions,
    /// IGI's bounding distance m.
    fade: f32,
    /// Photons the global map stored.
    pub photons_stored: u32,
    pub stats: Vec<GatherStats>,
}

impl BiasCompensation {
    /// The global map of `photons`, for `rays` gather rays a pixel that add
    /// what the bound at `fade` = m leaves out; None where the compensation
    /// is off (no rays) or the geometry term is unbounded (m = 0).
    pub fn prepare(
        p: &Prepare<'_>,
        (photons, estimate): (&PhotonConfig, &EstimateOptions),
        rays: u32,
        fade: f32,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Option<Self>> {
        if rays == 0 || fade <= 0.0 {
            return Ok(None);
        }
        observer.progress(&Progress::stage("bias compensation photons", 0, 1));
        let global = final_gather::global_scene(p.scene);
        let seed = final_gather::global_seed(p.seed);
        let built = photon::build_map(p.gpu, &global, p.textures, photons, seed, timings)?;
        let options = FinalGatherOptions {
            rays,
            ..FinalGatherOptions::default()
        };
        Ok(Some(Self {
            photons_stored: built.trace.stored,
            map: built.map,
            gather: FinalGather::new(p.gpu, p.width, p.height, options.rays)?,
            estimate: EstimateOptions {
                leak: options.leak,
                ..estimate.under(photons)
            },
            options,
            fade,
            stats: Vec::new(),
        }))
    }

    /// The light the bound left out at this sample's first hits.
    pub fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        let at = f.at;
        let stats = self.gather.run(
            f.textures,
            f.direct,
            f.direct.queries(),
            &self.map,
            &self.options,
            &self.estimate,
            f.scene.photon_map.max_radius,
            // Only a diffuse surface straight from x: no specular bounce.
            (0, self.fade),
            f.seed,
            timings,
            &mut |done, total| {
                observer.progress(&Progress::at(
                    "bias compensation",
                    done as u64,
                    total as u64,
                    at,
                ))
            },
        )?;
        self.stats.push(stats);
        Ok(self.gather.read_indirect())
    }

    /// k of the global map's estimate at the gather hits.
    pub fn k(&self) -> u32 {
        self.options.k
    }

    /// Gather rays a pixel per eye sample.
    pub fn rays(&self) -> u32 {
        self.options.rays
    }

    /// The bounding distance m whose loss it adds.
    pub fn fade(&self) -> f32 {
        self.fade
    }
}
