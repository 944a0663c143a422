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

/// Which light a method's caustic map carries: the light that reaches a
/// diffuse surface from a mirror or glass, which a method of point
/// connections or form factors (IGI, radiosity) cannot carry itself.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum CausticPaths {
    /// All of it, L (S|D)* S D: also the light a diffuse surface sends
    /// through mirrors and glass (L D+ S+ D), the paths traced on through
    /// diffuse hits and stored after specular bounces only.
    #[default]
    All,
    /// Jensen's caustic map, L S+ D: only light straight from an emitter
    /// through mirrors and glass, aimed by projection maps; L D+ S+ D is lost.
    FromLights,
}

/// k of a caustic map's estimate when a method gives none and the scene's
/// is larger. A caustic is sharp, so a larger k blurs it more than it cuts
/// the noise, and the scene's k may be a global map's (CORNELL BOX's 500).
/// Against the ground truth, 16 beats the paper's 32 (its GLASS BALL's k)
/// in CORNELL BOX and RING and ties in GLASS BALL, where 8 is much noisier
/// (the regions tables' "caustic map at k = 32" rows).
pub const CAUSTIC_K: u32 = 16;

/// The largest k a caustic map's estimate may be given: the scene's limit.
pub const MAX_K: u32 = crate::scene::defaults::MAX_K as u32;

/// What a method's caustic map carries, and the k of its estimate.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CausticMap {
    pub paths: CausticPaths,
    /// None: the scene's k, at most `CAUSTIC_K`.
    pub k: Option<u32>,
    /// Build on the scene's grid as it is, not the refined one.
    pub scene_grid: bool,
}

/// Cells of a refined caustic-map grid at most.
pub const CAUSTIC_GRID_CELLS: u64 = 1 << 22;

impl CausticMap {
    /// The k in use under a scene whose own is `scene_k`.
    pub fn k_for(&self, scene_k: u32) -> u32 {
        self.k.unwrap_or(scene_k.min(CAUSTIC_K))
    }

    /// The caustic map's grid. The kNN-grid resolves nothing finer than its
    /// cells, and a scene's grid is sized for its own k: a caustic map read
    /// at a smaller k_c gets cells (k / k_c)^(1/3) times finer on each axis
    /// (rounded), so that a cell holds about as many of its k_c photons as a
    /// scene cell held of k, at most `CAUSTIC_GRID_CELLS` cells.
    pub fn grid_resolution(&self, resolution: [u32; 3], scene_k: u32) -> [u32; 3] {
        let k = self.k_for(scene_k);
        if self.scene_grid || k >= scene_k {
            return resolution;
        }
        let mut factor = (f64::from(scene_k) / f64::from(k)).cbrt().round().max(1.0) as u32;
        let cells = |f: u32| {
            resolution
                .iter()
                .map(|&r| u64::from(r * f))
                .product::<u64>()
        };
        while factor > 1 && cells(factor) > CAUSTIC_GRID_CELLS {
            factor -= 1;
        }
        let side = crate::scene::defaults::MAX_GRID_SIDE as u32;
        resolution.map(|r| (r * factor).min(side))
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

#[cfg(test)]
mod tests {
    use super::*;

    fn map(k: Option<u32>, scene_grid: bool) -> CausticMap {
        CausticMap {
            paths: CausticPaths::All,
            k,
            scene_grid,
        }
    }

    #[test]
    fn the_caustic_grid_is_finer_by_the_cube_root_of_the_k_ratio() {
        // CORNELL BOX: k 500, caustic k 16: (500 / 16)^(1/3) = 3.15, so 3.
        assert_eq!(
            map(None, false).grid_resolution([25, 25, 50], 500),
            [75, 75, 150]
        );
        // GLASS BALL: k 32 -> 16: 1.26 rounds to 1, the scene's grid.
        assert_eq!(
            map(None, false).grid_resolution([250, 1, 250], 32),
            [250, 1, 250]
        );
        // RING: k 64 -> 16: 1.59 rounds to 2.
        assert_eq!(
            map(None, false).grid_resolution([250, 1, 250], 64),
            [500, 2, 500]
        );
        // A caustic k at or above the scene's, and the scene's grid asked for.
        assert_eq!(
            map(Some(64), false).grid_resolution([25, 25, 50], 64),
            [25, 25, 50]
        );
        assert_eq!(
            map(None, true).grid_resolution([25, 25, 50], 500),
            [25, 25, 50]
        );
    }

    #[test]
    fn the_refined_caustic_grid_stays_under_its_cell_budget() {
        // (4096 / 16)^(1/3) = 6.3 -> 6 would give 300^3 cells; the factor
        // drops to 3, the largest whose grid holds at most
        // CAUSTIC_GRID_CELLS (150^3 = 3.4M of 4.2M).
        let r = map(None, false).grid_resolution([50, 50, 50], 4096);
        assert_eq!(r, [150, 150, 150]);
        let cells: u64 = r.iter().map(|&s| u64::from(s)).product();
        assert!(cells <= CAUSTIC_GRID_CELLS);
    }
}
