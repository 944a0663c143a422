//! What a render is asked to do: the frame's size, seed and samples, and one
//! `Method`, whose arm carries that method's options and nothing else, so an
//! illegal combination (IGI with final gather, say) cannot be written down.

use crate::photon::PhotonConfig;
use crate::scene::Scene;

use super::differentials::DifferentialsOptions;
use super::igi::IgiOptions;
use super::photon_options::{PhotonMapOptions, WithCausticMap, WithPhotons};
use super::plan::FrameSize;
use super::radiance_estimate::EstimateOptions;
use super::radiosity::RadiosityOptions;
use super::sppm::options::SppmOptions;

/// How one render runs (what the scene file does not fix).
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub seed: u32,
    pub width: u32,
    pub height: u32,
    /// Shadow samples per area light drawn in one pass (bounds work per
    /// pass); 0 chooses by image size (`PassPlan::new`).
    pub shadow_batch: u32,
    /// Eye samples per pixel: 1 (the paper) shoots through the pixel centre;
    /// more are stratified, jittered and box-filtered.
    pub spp: u32,
    /// The light beyond direct light and specular paths, and how it is made.
    pub method: Method,
}

/// The global-illumination method of a render, with its options.
#[derive(Clone, Debug)]
pub enum Method {
    /// Direct light and specular paths only: no photons, no estimate.
    DirectOnly,
    /// The paper's photon map visualised at the first diffuse hits, with
    /// section 4.5's final gather and adaptive sampling as options.
    PhotonMap(PhotonMapOptions),
    /// Instant global illumination: VPLs for the diffuse interreflection,
    /// a caustic photon map for the caustics.
    Igi(WithCausticMap<IgiOptions>),
    /// Photon differentials: footprints in a BVH instead of the kNN-grid,
    /// one map for every photon.
    Differentials(WithPhotons<DifferentialsOptions>),
    /// Progressive refinement radiosity for the diffuse interreflection, a
    /// caustic photon map for the caustics.
    Radiosity(WithCausticMap<RadiosityOptions>),
    /// Stochastic progressive photon mapping: iterations of eye paths and
    /// photons, each pixel's radius shrinking; converges to the exact image.
    Sppm(WithPhotons<SppmOptions>),
}

impl Method {
    /// The method's name as provenance and reports spell it.
    pub fn name(&self) -> &'static str {
        match self {
            Method::DirectOnly => "direct-only",
            Method::PhotonMap(o) if o.final_gather.is_some() => "final-gather",
            Method::PhotonMap(_) => "paper",
            Method::Igi(_) => "igi",
            Method::Differentials(_) => "differentials",
            Method::Radiosity(_) => "radiosity",
            Method::Sppm(_) => "sppm",
        }
    }

    /// The photon tracer's configuration, where the method traces photons.
    pub fn photons(&self) -> Option<&PhotonConfig> {
        match self {
            Method::DirectOnly => None,
            Method::PhotonMap(o) => Some(&o.photons),
            Method::Igi(o) => Some(&o.photons),
            Method::Differentials(o) => Some(&o.photons),
            Method::Radiosity(o) => Some(&o.photons),
            Method::Sppm(o) => Some(&o.photons),
        }
    }

    /// The kNN-grid estimate's options, where the method runs one.
    pub fn estimate(&self) -> Option<&EstimateOptions> {
        match self {
            Method::DirectOnly | Method::Differentials(_) | Method::Sppm(_) => None,
            Method::PhotonMap(o) => Some(&o.estimate),
            Method::Igi(o) => Some(&o.estimate),
            Method::Radiosity(o) => Some(&o.estimate),
        }
    }

    /// The k of the kNN-grid estimate at the first hits under a scene whose
    /// own is `scene_k`: a caustic map's for IGI and radiosity.
    pub fn first_hit_k(&self, scene_k: u32) -> u32 {
        match self {
            Method::Igi(o) => o.method.caustic_map().k_for(scene_k),
            Method::Radiosity(o) => o.method.caustic_map().k_for(scene_k),
            _ => scene_k,
        }
    }

    /// The photon-map method's options, if this is it.
    pub fn photon_map(&self) -> Option<&PhotonMapOptions> {
        match self {
            Method::PhotonMap(o) => Some(o),
            _ => None,
        }
    }
}

impl RenderOptions {
    /// The scene's size, seed 1, one sample, the paper's photon map.
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            seed: 1,
            width: scene.camera.width,
            height: scene.camera.height,
            shadow_batch: 0,
            spp: 1,
            method: Method::PhotonMap(PhotonMapOptions::default()),
        }
    }

    pub fn direct_only(mut self) -> Self {
        self.method = Method::DirectOnly;
        self
    }

    /// The photon-map method's options, if it is the one chosen.
    pub fn photon_map_mut(&mut self) -> Option<&mut PhotonMapOptions> {
        match &mut self.method {
            Method::PhotonMap(o) => Some(o),
            _ => None,
        }
    }

    /// The same frame with another method.
    pub fn with_method(mut self, method: Method) -> Self {
        self.method = method;
        self
    }
}

impl From<&RenderOptions> for FrameSize {
    fn from(o: &RenderOptions) -> Self {
        FrameSize {
            width: o.width,
            height: o.height,
            spp: o.spp,
            shadow_batch: o.shadow_batch,
        }
    }
}
