//! What a frame render leaves behind: the image, its timings and plan, the
//! frame's GPU state, and the method's own state and reports, with
//! accessors that answer for whichever method ran.

use crate::image::Image;
use crate::photon::PhotonMap;
use crate::scene::pack::SceneTextures;
use crate::timing::Timings;

use super::adaptive::AdaptiveStats;
use super::differentials::{DifferentialsReport, FootprintStats};
use super::direct::DirectLight;
use super::final_gather::GatherStats;
use super::igi::{IgiStats, VplReport};
use super::method::MethodRun;
use super::photon_map::{MapEstimate, PhotonReport};
use super::plan::PassPlan;
use super::radiance_estimate::{EstimateStats, RadianceEstimate};
use super::radiosity::RadiosityReport;

/// A finished frame render.
pub struct RenderOutput {
    pub image: Image,
    pub timings: Timings,
    pub passes: usize,
    /// The ray tracer's passes as planned for the scene.
    pub plan: PassPlan,
    /// The frame's GPU state, for tests and the software reference.
    pub state: FrameState,
    /// The method's maps, textures and reports.
    pub method: MethodRun,
}

/// The scene's textures, and the last eye sample's direct light and first
/// diffuse hits.
pub struct FrameState {
    pub textures: SceneTextures,
    pub direct: DirectLight,
}

impl RenderOutput {
    /// The map visualised at the first hits by the kNN-grid estimate (the
    /// paper's, final gather's caustic map, IGI's and radiosity's caustic
    /// map), if one was made.
    pub fn first_map(&self) -> Option<&MapEstimate> {
        match &self.method {
            MethodRun::PhotonMap(m) => m.first.as_ref(),
            MethodRun::Igi(m) => m.caustics.as_ref(),
            MethodRun::Radiosity(m) => m.caustics.as_ref(),
            MethodRun::DirectOnly | MethodRun::Differentials(_) => None,
        }
    }

    /// How the map visualised at the first hits was made.
    pub fn photons(&self) -> Option<&PhotonReport> {
        self.first_map().map(|m| &m.report)
    }

    pub fn map(&self) -> Option<&PhotonMap> {
        self.first_map().map(|m| &m.map)
    }

    /// The radiance estimate's textures at the first hits.
    pub fn radiance_estimate(&self) -> Option<&RadianceEstimate> {
        self.first_map().map(|m| &m.estimate)
    }

    /// Every radiance estimate at the first hits (view by view, sample by
    /// sample), and the last.
    pub fn estimates(&self) -> &[EstimateStats] {
        self.first_map().map_or(&[], |m| &m.stats)
    }

    pub fn estimate(&self) -> Option<&EstimateStats> {
        self.estimates().last()
    }

    /// Final gather's global map report, and each eye sample's gather.
    pub fn gather_photons(&self) -> Option<&PhotonReport> {
        self.photon_map_run()?.gather.as_ref().map(|g| &g.report)
    }

    pub fn gathers(&self) -> &[GatherStats] {
        self.photon_map_run()
            .and_then(|m| m.gather.as_ref())
            .map_or(&[], |g| &g.stats)
    }

    /// Each eye sample's adaptive sampling.
    pub fn adaptive(&self) -> &[AdaptiveStats] {
        self.photon_map_run().map_or(&[], |m| &m.adaptive)
    }

    /// IGI's VPLs, and each eye sample's gather.
    pub fn vpls(&self) -> Option<&VplReport> {
        match &self.method {
            MethodRun::Igi(m) => Some(&m.report),
            _ => None,
        }
    }

    pub fn igi(&self) -> &[IgiStats] {
        match &self.method {
            MethodRun::Igi(m) => &m.stats,
            _ => &[],
        }
    }

    /// Photon differentials' map, and each eye sample's estimate.
    pub fn differentials(&self) -> Option<DifferentialsReport> {
        match &self.method {
            MethodRun::Differentials(m) => m.report(),
            _ => None,
        }
    }

    pub fn footprint_estimates(&self) -> &[FootprintStats] {
        match &self.method {
            MethodRun::Differentials(m) => &m.stats,
            _ => &[],
        }
    }

    /// The radiosity solution's report.
    pub fn radiosity(&self) -> Option<&RadiosityReport> {
        match &self.method {
            MethodRun::Radiosity(m) => Some(&m.report),
            _ => None,
        }
    }

    fn photon_map_run(&self) -> Option<&super::photon_map::PhotonMapRun> {
        match &self.method {
            MethodRun::PhotonMap(m) => Some(m),
            _ => None,
        }
    }
}

/// The methods' GPU state, for tests that read their textures.
impl RenderOutput {
    /// Final gather's gather textures and global map.
    pub fn gather(&self) -> Option<&super::final_gather::FinalGather> {
        self.photon_map_run()?.gather.as_ref().map(|g| &g.gather)
    }

    pub fn gather_map(&self) -> Option<&PhotonMap> {
        self.photon_map_run()?.gather.as_ref().map(|g| &g.map)
    }

    pub fn igi_run(&self) -> Option<&super::igi::IgiRun> {
        match &self.method {
            MethodRun::Igi(m) => Some(m),
            _ => None,
        }
    }

    pub fn differentials_run(&self) -> Option<&super::differentials::DifferentialsRun> {
        match &self.method {
            MethodRun::Differentials(m) => Some(m),
            _ => None,
        }
    }

    pub fn radiosity_run(&self) -> Option<&super::radiosity::RadiosityRun> {
        match &self.method {
            MethodRun::Radiosity(m) => Some(m),
            _ => None,
        }
    }

    pub fn radiosity_run_mut(&mut self) -> Option<&mut super::radiosity::RadiosityRun> {
        match &mut self.method {
            MethodRun::Radiosity(m) => Some(m),
            _ => None,
        }
    }
}
