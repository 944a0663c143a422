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
use super::vcm::options::VcmOptions;

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
    /// Render only these pixels of the frame (pbrt's crop window); the
    /// image is the crop. Pixel and photon streams stay the frame's, so
    /// tiles stitch into the full render bit for bit.
    pub pixel_bounds: Option<PixelBounds>,
    /// Eye paths by the paper's pass per bounce (eye rays, then per specular
    /// depth closest hits, shadow rays and the specular step) instead of one
    /// fused pass a path (`--faithful`); both give the same image.
    pub pass_per_bounce: bool,
}

/// A rectangle of the frame's pixels, half-open: columns x0..x1, rows
/// y0..y1 counted from the top (pbrt's `--pixelbounds`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct PixelBounds {
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

impl PixelBounds {
    pub fn width(&self) -> u32 {
        self.x1 - self.x0
    }

    pub fn height(&self) -> u32 {
        self.y1 - self.y0
    }

    /// Whether it is a non-empty part of a `width` x `height` frame.
    pub fn fits(&self, width: u32, height: u32) -> bool {
        self.x0 < self.x1 && self.y0 < self.y1 && self.x1 <= width && self.y1 <= height
    }

    /// pbrt's crop window: fractions [x0, x1) x [y0, y1) of the frame, from
    /// the top left, rounded to pixels as pbrt-v4 rounds them (each edge at
    /// the ceiling of its fraction of the side).
    pub fn of_crop_window(crop: [f64; 4], width: u32, height: u32) -> Self {
        let at = |f: f64, side: u32| ((f * side as f64).ceil() as u32).min(side);
        Self {
            x0: at(crop[0], width),
            x1: at(crop[1], width),
            y0: at(crop[2], height),
            y1: at(crop[3], height),
        }
    }

    /// These bounds grown by `margin` pixels on every side, within a
    /// `width` x `height` frame.
    pub fn grown(&self, margin: u32, width: u32, height: u32) -> Self {
        Self {
            x0: self.x0.saturating_sub(margin),
            x1: (self.x1 + margin).min(width),
            y0: self.y0.saturating_sub(margin),
            y1: (self.y1 + margin).min(height),
        }
    }

    /// The rectangle in GL's window coordinates (x, y from the bottom, w, h)
    /// of a frame `height` pixels high.
    pub fn gl_rect(&self, height: u32) -> [i32; 4] {
        [
            self.x0 as i32,
            (height - self.y1) as i32,
            self.width() as i32,
            self.height() as i32,
        ]
    }
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
    /// Vertex connection and merging: light and camera subpaths each
    /// iteration, every path taken by every technique that can make it
    /// (light tracing, path tracing, connections, merging), weighted by
    /// multiple importance sampling; progressive, as SPPM.
    Vcm(VcmOptions),
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
            Method::Vcm(_) => "vcm",
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
            Method::Vcm(_) => None,
        }
    }

    /// The kNN-grid estimate's options, where the method runs one.
    pub fn estimate(&self) -> Option<&EstimateOptions> {
        match self {
            Method::DirectOnly | Method::Differentials(_) | Method::Sppm(_) | Method::Vcm(_) => {
                None
            }
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
            pixel_bounds: None,
            pass_per_bounce: false,
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

    /// The part of a frame-sized `image` the pixel bounds keep (all of it
    /// without them).
    pub fn cut(&self, image: crate::image::Image) -> crate::image::Image {
        match self.pixel_bounds {
            Some(b) => image.crop(b.x0, b.y0, b.width(), b.height()),
            None => image,
        }
    }

    /// Refuses a scene with a rough metal (a glossy lobe) where this render
    /// cannot follow one: only the fused eye paths (and final gather's
    /// rays) sample and evaluate a glossy lobe, so direct light, the paper's
    /// method with or without final gather and SPPM render it, and not
    /// under `--faithful` (the paper's pass per bounce), IGI, differentials,
    /// radiosity or VCM.
    pub fn check_materials(&self, scene: &Scene) -> crate::error::Result<()> {
        let Some(material) = scene.glossy_material() else {
            return Ok(());
        };
        let what = match &self.method {
            _ if self.pass_per_bounce => "--faithful (the paper's pass per bounce)",
            Method::DirectOnly | Method::Sppm(_) | Method::PhotonMap(_) => return Ok(()),
            m => m.name(),
        };
        Err(crate::error::Error::InvalidOption(format!(
            "{what} cannot render a {} (alpha {}): only the fused eye paths follow a \
             glossy lobe; render it with --method sppm, the paper's method (with or \
             without final gather) or --direct-only, or make the metal smooth (alpha = 0)",
            material.kind_name(),
            match material {
                crate::scene::Material::Conductor { alpha, .. } => *alpha,
                _ => 0.0,
            }
        )))
    }

    /// Refuses pixel bounds that are empty or leave the frame.
    pub fn check_pixel_bounds(&self) -> crate::error::Result<()> {
        match self.pixel_bounds {
            Some(b) if !b.fits(self.width, self.height) => Err(crate::error::Error::out_of_range(
                "pixel_bounds",
                format!("{} {} {} {}", b.x0, b.x1, b.y0, b.y1),
                format!(
                    "x0 < x1 <= {} and y0 < y1 <= {} (pixels of the {} x {} frame)",
                    self.width, self.height, self.width, self.height
                ),
            )),
            _ => Ok(()),
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
            fused: !o.pass_per_bounce,
        }
    }
}
