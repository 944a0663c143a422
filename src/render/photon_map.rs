//! The photon-map method (the paper's frame): one map visualised at the
//! first diffuse hits by the kNN-grid estimate, or under final gather a
//! caustic map there and a global map at the gather rays' hits, either on
//! every pixel or (adaptive sampling) on a pyramid of pixel lattices.
//! `MapEstimate`, a map with its estimate, is also IGI's and radiosity's
//! caustic map.

use crate::gpu::{Gpu, Result};
use crate::image::Image;
use crate::photon::{self, BuiltMap, PhotonConfig, PhotonFrames, PhotonMap};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

use super::adaptive::{self, Adaptive, AdaptiveOptions, AdaptiveStats};
use super::direct::DirectLight;
use super::final_gather::{self, FinalGather, FinalGatherOptions, GatherStats};
use super::observer::{At, EstimatePass, Progress, RenderObserver};
use super::photon_options::{CausticMap, CausticPaths, PhotonMapOptions, WithCausticMap};
use super::radiance_estimate::{EstimateOptions, EstimateStats, QueryPoints, RadianceEstimate};
use super::sample::{FrameMethod, Prepare, SampleFrame};

/// The photon stage's report: `BuiltMap` without its map.
#[derive(Clone, Debug)]
pub struct PhotonReport {
    pub trace: photon::TraceReport,
    pub frames_traced: u32,
    pub grid: photon::Grid,
    pub grid_fitted: bool,
    pub build_stages: Timings,
    pub config: PhotonConfig,
}

impl PhotonReport {
    fn of(b: &BuiltMap, config: &PhotonConfig) -> Self {
        Self {
            trace: b.trace.clone(),
            frames_traced: b.frames_traced,
            grid: b.grid,
            grid_fitted: b.grid_fitted,
            build_stages: b.build_stages.clone(),
            config: config.clone(),
        }
    }
}

/// A photon map visualised at the first hits by the kNN-grid estimate: its
/// report, the map, the estimate's textures and each eye sample's estimate.
pub struct MapEstimate {
    pub report: PhotonReport,
    pub map: PhotonMap,
    pub estimate: RadianceEstimate,
    pub stats: Vec<EstimateStats>,
    options: EstimateOptions,
    /// The estimate's k where it is not the scene's (a caustic map's).
    k: Option<u32>,
}

impl MapEstimate {
    fn new(
        gpu: &Gpu,
        (w, h): (u32, u32),
        built: BuiltMap,
        photons: &PhotonConfig,
        estimate: &EstimateOptions,
    ) -> Result<Self> {
        Ok(Self::with_frames(gpu, (w, h), built, photons, estimate)?.0)
    }

    /// The map, and the traced records it was built from.
    fn with_frames(
        gpu: &Gpu,
        (w, h): (u32, u32),
        built: BuiltMap,
        photons: &PhotonConfig,
        estimate: &EstimateOptions,
    ) -> Result<(Self, PhotonFrames)> {
        let report = PhotonReport::of(&built, photons);
        let map = Self {
            report,
            map: built.map,
            estimate: RadianceEstimate::new(gpu, w, h)?,
            stats: Vec::new(),
            options: estimate.under(photons),
            k: None,
        };
        Ok((map, built.frames))
    }

    /// A caustic map (IGI's and radiosity's): the paths through mirrors or
    /// glass onto a diffuse surface, which their own diffuse light cannot
    /// carry, from an emitter only or from anywhere (`caustic.paths`), read
    /// with the caustic map's k; none in a scene with nothing specular.
    pub fn caustics<T>(
        p: &Prepare<'_>,
        o: &WithCausticMap<T>,
        caustic: CausticMap,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Option<Self>> {
        Ok(Self::caustics_with_records(p, o, caustic, timings, observer)?.map(|(map, _)| map))
    }

    /// The caustic map and the traced records it was built from.
    pub fn caustics_with_records<T>(
        p: &Prepare<'_>,
        o: &WithCausticMap<T>,
        caustic: CausticMap,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Option<(Self, PhotonFrames)>> {
        let (paths, k) = (caustic.paths, caustic.k_for(p.scene.photon_map.k));
        let resolution =
            caustic.grid_resolution(p.scene.photon_map.grid_resolution, p.scene.photon_map.k);
        observer.progress(&Progress::stage("photons", 0, 1));
        if !p.scene.has_specular() {
            return Ok(None);
        }
        let mut caustic = p.scene.clone();
        caustic.photon_map.caustics_only = paths == CausticPaths::FromLights;
        caustic.photon_map.specular_last_only = paths == CausticPaths::All;
        caustic.photon_map.store_direct = false;
        caustic.photon_map.grid_resolution = resolution;
        let built = photon::build_map(p.gpu, &caustic, p.textures, &o.photons, p.seed, timings)?;
        let size = (p.width, p.height);
        let (mut map, frames) = Self::with_frames(p.gpu, size, built, &o.photons, &o.estimate)?;
        map.k = Some(k);
        Ok(Some((map, frames)))
    }

    /// The estimate at `queries`, its image read back unless `packed`.
    pub fn run(
        &mut self,
        f: &SampleFrame<'_>,
        queries: QueryPoints<'_>,
        packed: bool,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Option<Image>> {
        let run = EstimateRun {
            scene: f.scene,
            textures: f.textures,
            direct: f.direct,
            queries,
            packed,
            map: &self.map,
            estimate: &self.estimate,
            options: &self.options,
            k: self.k.unwrap_or(f.scene.photon_map.k),
            at: f.at,
        };
        let (image, stats) = run.estimate(timings, observer)?;
        self.stats.push(stats);
        Ok(image)
    }

    /// The sample's image at its own first hits: the estimate composed with
    /// the direct light, or the direct light alone without a map.
    pub fn image_or_direct(
        map: Option<&mut Self>,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        match map {
            Some(m) => Ok(m
                .run(f, f.direct.queries(), false, timings, observer)?
                .expect("an unpacked run composes its image")),
            None => Ok(f.direct.read_radiance()),
        }
    }
}

/// Final gather's global map and gather textures, and each sample's gather.
pub struct GatherPart {
    pub report: PhotonReport,
    pub map: PhotonMap,
    pub gather: FinalGather,
    pub stats: Vec<GatherStats>,
    options: FinalGatherOptions,
}

/// The photon-map method's state through a render.
pub struct PhotonMapRun {
    /// The map visualised at the first hits (under final gather the caustic
    /// map; none when the scene has nothing specular).
    pub first: Option<MapEstimate>,
    pub gather: Option<GatherPart>,
    /// Adaptive sampling's pyramid, and each eye sample's report.
    pub pyramid: Option<Adaptive>,
    pub adaptive: Vec<AdaptiveStats>,
    adaptive_options: AdaptiveOptions,
    estimate: EstimateOptions,
}

impl PhotonMapRun {
    /// Traces the photons and builds the map (or final gather's two).
    pub fn prepare(
        p: &Prepare<'_>,
        o: &PhotonMapOptions,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let (gpu, scene, textures, seed) = (p.gpu, p.scene, p.textures, p.seed);
        let (w, h) = (p.width, p.height);
        observer.progress(&Progress::stage("photons", 0, 1));
        let (first, gather) = match &o.final_gather {
            None => {
                let built = photon::build_map(gpu, scene, textures, &o.photons, seed, timings)?;
                (Some(built), None)
            }
            Some(fg) => {
                let (caustic, global) = final_gather::map_scenes(scene)?;
                let caustic = if scene.has_specular() {
                    Some(photon::build_map(
                        gpu, &caustic, textures, &o.photons, seed, timings,
                    )?)
                } else {
                    None
                };
                let global_seed = final_gather::global_seed(seed);
                let global =
                    photon::build_map(gpu, &global, textures, &o.photons, global_seed, timings)?;
                (caustic, Some((global, fg)))
            }
        };
        let first = first
            .map(|b| MapEstimate::new(gpu, (w, h), b, &o.photons, &o.estimate))
            .transpose()?;
        let gather = match gather {
            None => None,
            Some((global, fg)) => Some(GatherPart {
                report: PhotonReport::of(&global, &o.photons),
                map: global.map,
                gather: FinalGather::new(gpu, w, h, fg.rays)?,
                stats: Vec::new(),
                options: fg.clone(),
            }),
        };
        Ok(Self {
            first,
            gather,
            pyramid: o
                .adaptive
                .is_some()
                .then(|| Adaptive::new(gpu, w, h))
                .transpose()?,
            adaptive: Vec::new(),
            adaptive_options: o.adaptive.clone().unwrap_or_default(),
            estimate: o.estimate_options(),
        })
    }

    /// The estimate and the gather at `queries`. Their light is left in
    /// their textures (the estimate's composed `image` without direct light
    /// when `packed`, the gather's `indirect`); unpacked, it is also read back
    /// as the sample's image with its direct light. Packed (adaptive
    /// sampling's levels), nothing is read back.
    fn global_light(
        &mut self,
        f: &SampleFrame<'_>,
        queries: QueryPoints<'_>,
        packed: bool,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Option<Image>> {
        let mut image = match &mut self.first {
            Some(m) => m.run(f, queries, packed, timings, observer)?,
            None if packed => None,
            None => Some(f.direct.read_radiance()),
        };
        if let Some(g) = &mut self.gather {
            let estimate = EstimateOptions {
                leak: g.options.leak,
                ..self.estimate.clone()
            };
            let run = GatherRun {
                scene: f.scene,
                textures: f.textures,
                direct: f.direct,
                queries,
                global: &g.map,
                gather: &g.gather,
                options: &g.options,
                estimate: &estimate,
                at: f.at,
            };
            g.stats.push(run.gather(f.seed, timings, observer)?);
            if let Some(image) = &mut image {
                image.add(&g.gather.read_indirect());
            }
        }
        Ok(image)
    }

    /// Adaptive sampling's levels: global light computed on the pyramid's
    /// packed pixels, interpolated at the rest.
    fn adaptive_sample(
        &mut self,
        pyramid: &Adaptive,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        pyramid.clear();
        let mut stats = AdaptiveStats::default();
        for level in 0..adaptive::STRIDES.len() {
            let t0 = std::time::Instant::now();
            let plan = pyramid.select(f.direct, level, &self.adaptive_options)?;
            let (computed, interpolated) =
                (plan.computed.len() as u64, plan.interpolated.len() as u64);
            timings.add_since("adaptive plan", 0.0, t0, 2);
            if computed > 0 {
                // The estimate and gather run on the packed first hits.
                let packed = SampleFrame {
                    direct: &pyramid.packed,
                    ..*f
                };
                self.global_light(&packed, pyramid.queries(), true, timings, observer)?;
            }
            let t0 = std::time::Instant::now();
            pyramid.store(
                self.first.as_ref().map(|m| &m.estimate.image),
                self.gather.as_ref().map(|g| &g.gather.indirect),
            )?;
            timings.add_since("adaptive plan", 0.0, t0, 1);
            stats.computed += computed;
            stats.interpolated += interpolated;
            stats
                .levels
                .push((adaptive::STRIDES[level], computed, interpolated));
        }
        stats.pixels_with_hits = stats.computed + stats.interpolated;
        self.adaptive.push(stats);
        let mut image = f.direct.read_radiance();
        image.add(&pyramid.read_value());
        Ok(image)
    }
}

impl FrameMethod for PhotonMapRun {
    /// Its direct light, plus the estimate at its first hits and (final
    /// gather) the gathered indirect light, computed at every pixel or
    /// (adaptive) on the pyramid.
    fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        // Taken for the levels and put back: global_light borrows self.
        let Some(pyramid) = self.pyramid.take() else {
            let image = self.global_light(f, f.direct.queries(), false, timings, observer)?;
            return Ok(image.expect("an unpacked run composes its image"));
        };
        let image = self.adaptive_sample(&pyramid, f, timings, observer);
        self.pyramid = Some(pyramid);
        image
    }
}

/// One eye sample's final gather: the global map, the first diffuse hits and
/// the gather's textures.
struct GatherRun<'a> {
    scene: &'a Scene,
    textures: &'a SceneTextures,
    direct: &'a DirectLight,
    /// The first hits to gather at.
    queries: QueryPoints<'a>,
    global: &'a PhotonMap,
    gather: &'a FinalGather,
    options: &'a FinalGatherOptions,
    estimate: &'a EstimateOptions,
    at: At,
}

impl GatherRun<'_> {
    fn gather(
        &self,
        seed: u32,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<GatherStats> {
        let at = self.at;
        self.gather.run(
            self.textures,
            self.direct,
            self.queries,
            self.global,
            self.options,
            self.estimate,
            self.scene.photon_map.max_radius,
            (self.scene.render.max_specular_depth, 0.0),
            seed,
            timings,
            &mut |done, total| {
                observer.progress(&Progress::at("final gather", done as u64, total as u64, at))
            },
        )
    }
}

/// One radiance estimate: a map, the first diffuse hits of one eye sample,
/// and the estimate's state textures.
struct EstimateRun<'a> {
    scene: &'a Scene,
    textures: &'a SceneTextures,
    direct: &'a DirectLight,
    queries: QueryPoints<'a>,
    /// Adaptive sampling's packed queries: the estimate is composed without
    /// direct light and left on the GPU, and the observer sees only progress
    /// (a packed level is no image).
    packed: bool,
    map: &'a PhotonMap,
    estimate: &'a RadianceEstimate,
    options: &'a EstimateOptions,
    k: u32,
    at: At,
}

impl EstimateRun<'_> {
    /// Runs the estimate to the end and composes the image (read back unless
    /// packed). The observer sees every pass and the final state; its own
    /// time is not counted.
    fn estimate(
        &self,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<(Option<Image>, EstimateStats)> {
        let (k, max_radius) = (self.k, self.scene.photon_map.max_radius);
        let options = self.options;
        let compose = || -> Result<Image> {
            self.estimate
                .draw_composed(self.textures, self.direct, k, max_radius, true, true)?;
            Ok(self.estimate.composed_image())
        };
        let mut observed = 0.0;
        let mut failure = None;
        let stats = self.estimate.run(
            self.textures,
            self.map,
            self.queries,
            k,
            max_radius,
            options,
            &mut |r| {
                let t0 = std::time::Instant::now();
                observer.progress(&Progress::at(
                    "radiance estimate",
                    r.query_pixels - r.searching,
                    r.query_pixels,
                    self.at,
                ));
                if self.packed {
                    return;
                }
                let pass = EstimatePass {
                    stopped_by: None,
                    at: self.at,
                    pass: r.pass,
                    searching: r.searching,
                    query_pixels: r.query_pixels,
                    seconds: r.elapsed_seconds - observed,
                    finished: false,
                    image: &compose,
                };
                if failure.is_none() {
                    failure = observer.estimate_pass(&pass).err();
                }
                observed += t0.elapsed().as_secs_f64();
            },
        )?;
        if let Some(e) = failure {
            return Err(e);
        }
        let seconds = stats.wall_seconds - observed;
        timings.add_both(
            "radiance estimate",
            stats.gpu_seconds,
            seconds,
            stats.passes as usize,
        );
        if self.packed {
            self.estimate
                .draw_composed(self.textures, self.direct, k, max_radius, false, true)?;
            return Ok((None, stats));
        }
        let image = compose()?;
        observer.estimate_pass(&EstimatePass {
            stopped_by: None,
            at: self.at,
            pass: stats.passes,
            searching: 0,
            query_pixels: stats.query_pixels,
            seconds,
            finished: true,
            image: &|| Ok(image.clone()),
        })?;
        Ok((Some(image), stats))
    }
}
