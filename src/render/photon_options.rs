//! The photon tracer's and the kNN estimate's options as the methods take
//! them: the photon-map method's, and another method's own options beside
//! its caustic map's or its photons'.

use crate::photon::PhotonConfig;

use super::adaptive::AdaptiveOptions;
use super::final_gather::FinalGatherOptions;
use super::radiance_estimate::EstimateOptions;

/// The paper's photon map and its section 4.5 options.
#[derive(Clone, Debug, Default)]
pub struct PhotonMapOptions {
    pub photons: PhotonConfig,
    pub estimate: EstimateOptions,
    /// Final gather: a caustic map at the first hits and a global map at the
    /// gather rays' hits, instead of the one map visualised directly.
    pub final_gather: Option<FinalGatherOptions>,
    /// Adaptive sampling: global light computed on a pyramid of pixel
    /// lattices and interpolated where it is smooth.
    pub adaptive: Option<AdaptiveOptions>,
}

impl PhotonMapOptions {
    /// The estimate's options as the photon config constrains them.
    pub fn estimate_options(&self) -> EstimateOptions {
        self.estimate.under(&self.photons)
    }
}

/// A method's own options beside those of the caustic photon map it
/// visualises at the first hits.
#[derive(Clone, Debug, Default)]
pub struct WithCausticMap<T> {
    pub photons: PhotonConfig,
    pub estimate: EstimateOptions,
    pub method: T,
}

/// A method's own options beside those of the photons it traces.
#[derive(Clone, Debug, Default)]
pub struct WithPhotons<T> {
    pub photons: PhotonConfig,
    pub method: T,
}

impl<T> WithPhotons<T> {
    /// The photon map's photons for `method`.
    pub fn from_map(map: PhotonMapOptions, method: T) -> Self {
        Self {
            photons: map.photons,
            method,
        }
    }
}

impl<T> WithCausticMap<T> {
    /// The photon map's photons and estimate as `method`'s caustic map.
    pub fn from_map(map: PhotonMapOptions, method: T) -> Self {
        Self {
            photons: map.photons,
            estimate: map.estimate,
            method,
        }
    }

    /// The estimate's options as the photon config constrains them.
    pub fn estimate_options(&self) -> EstimateOptions {
        self.estimate.under(&self.photons)
    }
}
