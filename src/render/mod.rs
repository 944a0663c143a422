//! The frame, as the paper's Figure 1 draws it: trace photons and build the
//! photon map (`photon::build_map`), then for each view and eye sample ray
//! trace the scene and take the radiance estimate at each first diffuse hit,
//! and average the samples into the image.

pub mod adaptive;
pub mod differentials;
pub mod direct;
pub mod explain;
pub mod final_gather;
pub mod igi;
pub mod observer;
pub mod plan;
pub mod radiance_estimate;
pub mod radiosity;
pub mod ray_rates;
pub mod ray_trace;
pub mod search_work;
pub mod software;
pub mod sppm;
pub mod sppm_adaptive;

use crate::error::Error;
use crate::gpu::{Gpu, Result};
use crate::photon::{self, BuiltMap, PhotonConfig, PhotonMap};
use crate::scene::pack::SceneTextures;
use crate::scene::{Camera, Scene};

pub use crate::image::Image;
pub use crate::timing::{StageTiming, Timings};
pub use adaptive::{Adaptive, AdaptiveOptions, AdaptiveStats};
pub use differentials::{
    DifferentialPhotons, DifferentialsOptions, FootprintEstimate, FootprintStats, Kernel,
};
pub use direct::DirectLight;
pub use explain::ExplainLine;
pub use final_gather::{FinalGather, FinalGatherOptions, GatherStats};
pub use igi::{Igi, IgiOptions, IgiStats, VplReport, Vpls};
pub use observer::{EstimatePass, Progress, RenderObserver, StopReason};
pub use plan::PassPlan;
pub use radiance_estimate::{
    EstimateMode, EstimateOptions, EstimateStats, QueryPoints, RadianceEstimate,
};
pub use radiosity::{Radiosity, RadiosityOptions, RadiosityReport};
pub use ray_trace::{HitBuffers, RayBuffers, RayTracer};

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
    /// Photon map and radiance estimate; None draws direct light and specular paths only.
    pub global: Option<GlobalIllumination>,
}

/// The photon-mapping half of a render.
#[derive(Clone, Debug, Default)]
pub struct GlobalIllumination {
    pub photons: PhotonConfig,
    pub estimate: EstimateOptions,
    /// Final gather (section 4.5): a caustic map at the first hits and a global
    /// map at the gather rays' hits, instead of the one map visualised directly.
    pub final_gather: Option<FinalGatherOptions>,
    /// Adaptive sampling (section 4.5): global light computed on a pyramid of
    /// pixel lattices and interpolated where it is smooth.
    pub adaptive: Option<AdaptiveOptions>,
    /// Instant global illumination (`--method igi`): VPLs for the diffuse
    /// interreflection, and the photon map for caustics only.
    pub igi: Option<IgiOptions>,
    /// Photon differentials with a BVH photon map (`--method differentials`):
    /// footprints instead of the kNN-grid, one map for every photon.
    pub differentials: Option<DifferentialsOptions>,
    /// Progressive refinement radiosity (`--method radiosity`): the diffuse
    /// interreflection from an element atlas, caustics from a caustic map.
    pub radiosity: Option<RadiosityOptions>,
}

impl GlobalIllumination {
    /// The estimate's options as the photon config constrains them: under
    /// `--faithful`, the paper's float addressing and the paper's walk.
    fn estimate_options(&self) -> EstimateOptions {
        let faithful = self.photons.faithful;
        EstimateOptions {
            float_addressing: faithful,
            cull: self.estimate.cull && !faithful,
            runs: self.estimate.runs && !faithful,
            ..self.estimate.clone()
        }
    }
}

impl RenderOptions {
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            seed: 1,
            width: scene.camera.width,
            height: scene.camera.height,
            shadow_batch: 0,
            spp: 1,
            global: Some(GlobalIllumination::default()),
        }
    }

    pub fn direct_only(mut self) -> Self {
        self.global = None;
        self
    }
}

/// What a render leaves behind.
pub struct RenderOutput {
    pub image: Image,
    /// The GPU state behind the image, for tests and the software reference.
    pub state: RenderState,
    pub timings: Timings,
    pub passes: usize,
    /// The ray tracer's passes as planned for the scene.
    pub plan: PassPlan,
    /// How the photon map visualised at the first hits was made (None: direct
    /// light only, or final gather in a scene with nothing specular).
    pub photons: Option<PhotonReport>,
    /// Final gather's global map, and each eye sample's gather.
    pub gather_photons: Option<PhotonReport>,
    pub gathers: Vec<GatherStats>,
    /// Each eye sample's adaptive sampling.
    pub adaptive: Vec<AdaptiveStats>,
    /// IGI's VPLs, and each eye sample's gather.
    pub vpls: Option<VplReport>,
    pub igi: Vec<IgiStats>,
    /// Photon differentials' map, and each eye sample's estimate.
    pub differentials: Option<DifferentialsReport>,
    pub footprint_estimates: Vec<FootprintStats>,
    /// The radiosity solution's report.
    pub radiosity: Option<RadiosityReport>,
    /// The last radiance estimate, and every one (view by view, sample by sample).
    pub estimate: Option<EstimateStats>,
    pub estimates: Vec<EstimateStats>,
}

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

/// The GPU resources of a finished render.
pub struct RenderState {
    pub textures: SceneTextures,
    /// Direct light and each eye path's first diffuse hit.
    pub direct: DirectLight,
    pub map: Option<PhotonMap>,
    pub estimate: Option<RadianceEstimate>,
    /// Final gather's global map, and its textures (the last batch's gather hits).
    pub gather_map: Option<PhotonMap>,
    pub gather: Option<FinalGather>,
    /// IGI's VPLs and gather textures (the last eye sample's).
    pub vpls: Option<Vpls>,
    pub igi: Option<Igi>,
    /// Photon differentials' photons, footprint map and estimate textures.
    pub differentials: Option<DifferentialsRun>,
    /// The radiosity solution's atlas and passes.
    pub radiosity: Option<Radiosity>,
}

/// What the photon-differentials map was made of.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DifferentialsReport {
    pub trace: photon::TraceReport,
    pub frames_traced: u32,
    pub footprints: u32,
    /// Footprints of photons reflected diffusely before (the others: caustics).
    pub diffuse_footprints: u32,
    pub degenerate_footprints: u32,
    /// The share of the stored power those carry (lost to the estimate).
    pub degenerate_power_fraction: f64,
    /// s in use, and (auto) the pilot's mean footprints a hit at s = 1, all
    /// and diffuse.
    pub smoothing: f32,
    pub pilot_mean_footprints: Option<f64>,
    pub pilot_mean_diffuse_footprints: Option<f64>,
    pub caustic_smoothing: f32,
    pub max_radius: f32,
    pub kernel: Kernel,
    pub leaf_size: u32,
    pub auto_leaf_size: u32,
    pub leaves: u32,
    pub total_footprint_area: f64,
    pub surface_area: f64,
    pub delta: f32,
}

/// Photon differentials' GPU state: the photons, the map (made on the first
/// eye sample, after the pilot when s is automatic) and the estimate.
pub struct DifferentialsRun {
    pub photons: DifferentialPhotons,
    pub map: Option<photon::differentials::FootprintMap>,
    pub estimate: FootprintEstimate,
    builder: photon::differentials::FootprintBuilder,
    options: DifferentialsOptions,
    /// The pilot's mean footprints a hit: all, and diffuse.
    pilot_mean: Option<(f64, f64)>,
}

impl DifferentialsRun {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        textures: &SceneTextures,
        gi: &GlobalIllumination,
        o: &DifferentialsOptions,
        (w, h, seed): (u32, u32, u32),
        timings: &mut Timings,
    ) -> Result<Self> {
        o.check()?;
        let tracer = photon::PhotonTracer::with_config(gpu, gi.photons.trace())?;
        let photons = DifferentialPhotons::trace(gpu, scene, textures, &tracer, seed, timings)?;
        Ok(Self {
            photons,
            map: None,
            estimate: FootprintEstimate::new(gpu, w, h, o.kernel)?,
            builder: photon::differentials::FootprintBuilder::new(gpu)?,
            options: o.clone(),
            pilot_mean: None,
        })
    }

    /// The map, built on first use: after a pilot at s = 1 over these first
    /// hits when s is automatic ("smoothing pilot").
    fn ensure_map(&mut self, f: &SampleFrame<'_>, timings: &mut Timings) -> Result<()> {
        if self.map.is_none() {
            let smoothing = match self.options.smoothing {
                Some(s) => s,
                None => {
                    let t0 = std::time::Instant::now();
                    let mut pilot_timings = Timings::default();
                    let options = self.options.footprint_options(f.scene, 1.0);
                    let pilot = self.builder.build(
                        f.scene,
                        &self.photons.frames,
                        &self.photons.differentials,
                        &options,
                        &mut pilot_timings,
                    )?;
                    if pilot.diffuse == 0 {
                        // Caustics only: s touches no footprint, the pilot is the map.
                        timings.add_both(
                            "footprint map",
                            pilot_timings.gpu_total(),
                            t0.elapsed().as_secs_f64(),
                            pilot_timings.stages.iter().map(|s| s.passes).sum(),
                        );
                        self.map = Some(pilot);
                        return Ok(());
                    }
                    let stats = self.estimate.run(
                        f.textures,
                        f.direct,
                        &pilot,
                        &mut pilot_timings,
                        &mut |_, _| {},
                    )?;
                    timings.add_both(
                        "smoothing pilot",
                        0.0,
                        t0.elapsed().as_secs_f64(),
                        pilot_timings.stages.iter().map(|s| s.passes).sum(),
                    );
                    self.pilot_mean = Some((stats.mean_footprints, stats.mean_diffuse_footprints));
                    differentials::smoothing_for(
                        f.scene.photon_map.k,
                        stats.mean_footprints,
                        stats.mean_diffuse_footprints,
                    )
                    .unwrap_or(1.0)
                }
            };
            let options = self.options.footprint_options(f.scene, smoothing);
            let t0 = std::time::Instant::now();
            let mut stages = Timings::default();
            let map = self.builder.build(
                f.scene,
                &self.photons.frames,
                &self.photons.differentials,
                &options,
                &mut stages,
            )?;
            timings.add_both(
                "footprint map",
                stages.gpu_total(),
                t0.elapsed().as_secs_f64(),
                stages.stages.iter().map(|s| s.passes).sum(),
            );
            self.map = Some(map);
        }
        Ok(())
    }

    fn report(&self) -> Option<DifferentialsReport> {
        let m = self.map.as_ref()?;
        Some(DifferentialsReport {
            trace: self.photons.trace.clone(),
            frames_traced: self.photons.frames.frames,
            footprints: m.count,
            diffuse_footprints: m.diffuse,
            degenerate_footprints: m.degenerate,
            degenerate_power_fraction: m.degenerate_power_fraction,
            smoothing: m.options.smoothing,
            pilot_mean_footprints: self.pilot_mean.map(|m| m.0),
            pilot_mean_diffuse_footprints: self.pilot_mean.map(|m| m.1),
            caustic_smoothing: m.options.caustic_smoothing,
            max_radius: m.options.max_radius,
            kernel: self.options.kernel,
            leaf_size: m.leaf_size,
            auto_leaf_size: m.auto_leaf_size,
            leaves: m.leaves,
            total_footprint_area: m.total_area,
            surface_area: m.surface_area,
            delta: m.delta,
        })
    }
}

/// Renders a scene: the paper's ray tracer (direct light, specular paths) and,
/// with `options.global`, photon tracing, the photon map and the kNN-grid
/// radiance estimate at each eye path's first diffuse hit. With `spp` > 1 the
/// photon map is built once and each eye sample (stratified, jittered) runs the
/// ray tracer and the estimate; the image is their mean (a box filter).
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    observer: &mut dyn RenderObserver,
) -> Result<RenderOutput> {
    render_views(
        gpu,
        scene,
        options,
        std::slice::from_ref(&scene.camera),
        observer,
    )
}

/// Renders the scene from each camera in turn on one photon map (the paper's
/// figure 1: photons are traced and the map built only when geometry or lights
/// change). The observer sees each view's image; the output holds the last.
pub fn render_views(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    cameras: &[Camera],
    observer: &mut dyn RenderObserver,
) -> Result<RenderOutput> {
    check_request(gpu, options, cameras)?;
    let plan = PassPlan::new(scene, options);
    let (w, h) = (options.width, options.height);
    let textures = SceneTextures::new(gpu, scene)?;
    let tracer = RayTracer::new(gpu, w, h)?;
    let direct = DirectLight::new(gpu, w, h)?;
    let mut timings = Timings::default();
    let wall = std::time::Instant::now();
    // Photons first: one map (or final gather's two) serves every view and
    // every eye sample.
    let mut global = GlobalPart::new(gpu, scene, &textures, options, &mut timings, observer)?;
    let mut image = None;
    for (view, camera) in cameras.iter().enumerate() {
        let mut sum = ImageSum::default();
        for sample in 0..plan.spp {
            crate::interrupt::check()?;
            let at = At {
                view,
                views: cameras.len(),
                sample,
                samples: plan.spp,
            };
            let eye = EyeSample {
                camera,
                sample,
                seed: crate::random::sample_seed(options.seed, sample),
            };
            trace_eye_paths(
                gpu,
                &plan,
                &textures,
                &tracer,
                &direct,
                &eye,
                &mut timings,
                observer,
                at,
            )?;
            let frame = SampleFrame {
                scene,
                camera_position: camera.position,
                textures: &textures,
                direct: &direct,
                options,
                seed: eye.seed,
                at,
            };
            sum.add(&global.sample(&frame, &mut timings, observer)?);
        }
        let view_image = sum.mean();
        observer.frame(view, &view_image)?;
        image = Some(view_image);
    }
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    let GlobalPart {
        built,
        global_map,
        estimate,
        gather,
        estimates,
        gathers,
        adaptive,
        vpls,
        igi,
        igi_stats,
        differentials,
        footprint_stats,
        radiosity,
        ..
    } = global;
    let mut output = finish(
        image.expect("at least one camera"),
        timings,
        plan,
        built,
        estimates,
        options,
        RenderState {
            textures,
            direct,
            map: None,
            estimate,
            gather_map: None,
            gather,
            vpls: None,
            igi: None,
            differentials: None,
            radiosity: None,
        },
    );
    if let Some(g) = global_map {
        output.gather_photons = Some(report_of(&g, options));
        output.state.gather_map = Some(g.map);
    }
    output.gathers = gathers;
    output.adaptive = adaptive;
    output.vpls = vpls.as_ref().map(|v| VplReport {
        paths: v.paths,
        vpls: v.count,
        frames_traced: v.frames_traced,
        min_distance: options
            .global
            .as_ref()
            .and_then(|g| g.igi.as_ref())
            .map_or(0.0, |o| o.min_distance_for(scene)),
    });
    output.igi = igi_stats;
    output.state.vpls = vpls;
    output.state.igi = igi;
    output.attach_methods(differentials, footprint_stats, radiosity);
    Ok(output)
}

impl RenderOutput {
    /// Photon differentials' and radiosity's reports and GPU state.
    fn attach_methods(
        &mut self,
        differentials: Option<DifferentialsRun>,
        footprint_stats: Vec<FootprintStats>,
        radiosity: Option<(Radiosity, RadiosityReport)>,
    ) {
        self.differentials = differentials.as_ref().and_then(DifferentialsRun::report);
        self.footprint_estimates = footprint_stats;
        self.state.differentials = differentials;
        if let Some((r, report)) = radiosity {
            self.radiosity = Some(report);
            self.state.radiosity = Some(r);
        }
    }
}

/// One eye sample's first hits, ready for the global half.
#[derive(Clone, Copy)]
struct SampleFrame<'a> {
    scene: &'a Scene,
    /// The eye (IGI's discontinuity buffer measures depth from it).
    camera_position: glam::Vec3,
    textures: &'a SceneTextures,
    direct: &'a DirectLight,
    options: &'a RenderOptions,
    seed: u32,
    at: At,
}

/// The photon-mapping half of a frame: the maps, the estimators' textures and
/// what each eye sample's estimate and gather did.
struct GlobalPart {
    built: Option<BuiltMap>,
    global_map: Option<BuiltMap>,
    estimate: Option<RadianceEstimate>,
    gather: Option<FinalGather>,
    estimates: Vec<EstimateStats>,
    gathers: Vec<GatherStats>,
    pyramid: Option<Adaptive>,
    adaptive: Vec<AdaptiveStats>,
    /// IGI's VPLs and gather, and each eye sample's report.
    vpls: Option<Vpls>,
    igi: Option<Igi>,
    igi_stats: Vec<IgiStats>,
    /// Photon differentials' run, and each eye sample's estimate.
    differentials: Option<DifferentialsRun>,
    footprint_stats: Vec<FootprintStats>,
    radiosity: Option<(Radiosity, RadiosityReport)>,
}

impl GlobalPart {
    fn new(
        gpu: &Gpu,
        scene: &Scene,
        textures: &SceneTextures,
        options: &RenderOptions,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let (w, h) = (options.width, options.height);
        let (built, global_map) = match &options.global {
            None => (None, None),
            Some(gi) => {
                observer.progress(&Progress::stage("photons", 0, 1));
                build_maps(gpu, scene, textures, gi, options.seed, timings)?
            }
        };
        let estimate = built
            .as_ref()
            .map(|_| RadianceEstimate::new(gpu, w, h))
            .transpose()?;
        let rays = options
            .global
            .as_ref()
            .and_then(|g| g.final_gather.as_ref())
            .map(|fg| fg.rays);
        let gather = match (rays, &global_map) {
            (Some(rays), Some(_)) => Some(FinalGather::new(gpu, w, h, rays)?),
            _ => None,
        };
        let adaptive = options
            .global
            .as_ref()
            .is_some_and(|g| g.adaptive.is_some());
        let (vpls, igi) = match options.global.as_ref().and_then(|g| g.igi.as_ref()) {
            None => (None, None),
            Some(o) => {
                if adaptive
                    || options
                        .global
                        .as_ref()
                        .is_some_and(|g| g.final_gather.is_some())
                {
                    return Err(Error::InvalidOption(
                        "IGI has its own accelerations (--interleave, --downsample): drop --adaptive and --final-gather".into(),
                    ));
                }
                let igi = Igi::new(gpu, scene, w, h, o)?;
                observer.progress(&Progress::stage("VPLs", 0, 1));
                let seed = crate::random::pcg_hash(options.seed ^ crate::layout::VPL_STREAM);
                let vpls = Vpls::trace(
                    gpu,
                    scene,
                    textures,
                    (o.vpl_paths, o.vpl_bounces),
                    seed,
                    timings,
                )?;
                (Some(vpls), Some(igi))
            }
        };
        let differentials =
            differentials_run(gpu, scene, textures, options, adaptive, timings, observer)?;
        let radiosity = radiosity_run(gpu, scene, textures, options, adaptive, timings, observer)?;
        Ok(Self {
            built,
            global_map,
            estimate,
            gather,
            estimates: Vec::new(),
            gathers: Vec::new(),
            pyramid: adaptive.then(|| Adaptive::new(gpu, w, h)).transpose()?,
            adaptive: Vec::new(),
            vpls,
            igi,
            igi_stats: Vec::new(),
            differentials,
            footprint_stats: Vec::new(),
            radiosity,
        })
    }

    /// One eye sample's image: its direct light, plus the estimate at its
    /// first hits and (final gather) the gathered indirect light, computed at
    /// every pixel or (adaptive) on the pyramid.
    fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        let Some(gi) = &f.options.global else {
            return Ok(f.direct.read_radiance());
        };
        // Taken for the levels and put back: global_light borrows self.
        let Some(pyramid) = self.pyramid.take() else {
            let image = self.global_light(f, gi, f.direct.queries(), false, timings, observer)?;
            return Ok(image.expect("an unpacked run composes its image"));
        };
        let options = gi.adaptive.clone().unwrap_or_default();
        pyramid.clear();
        let mut stats = AdaptiveStats::default();
        for level in 0..adaptive::STRIDES.len() {
            let t0 = std::time::Instant::now();
            let plan = pyramid.select(f.direct, level, &options)?;
            let (computed, interpolated) =
                (plan.computed.len() as u64, plan.interpolated.len() as u64);
            timings.add_both("adaptive plan", 0.0, t0.elapsed().as_secs_f64(), 2);
            if computed > 0 {
                // The estimate and gather run on the packed first hits.
                let packed = SampleFrame {
                    direct: &pyramid.packed,
                    ..*f
                };
                let queries = pyramid.queries();
                self.global_light(&packed, gi, queries, true, timings, observer)?;
            }
            let t0 = std::time::Instant::now();
            pyramid.store(
                self.estimate
                    .as_ref()
                    .filter(|_| self.built.is_some())
                    .map(|e| &e.image),
                self.gather.as_ref().map(|g| &g.indirect),
            )?;
            timings.add_both("adaptive plan", 0.0, t0.elapsed().as_secs_f64(), 1);
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
        self.pyramid = Some(pyramid);
        Ok(image)
    }

    /// The estimate and the gather at `queries`. Their light is left in
    /// their textures (the estimate's composed `image` without direct light
    /// when `packed`, the gather's `indirect`); unpacked, it is also read back
    /// as the sample's image with its direct light. Packed (adaptive
    /// sampling's levels), nothing is read back.
    fn global_light(
        &mut self,
        f: &SampleFrame<'_>,
        gi: &GlobalIllumination,
        queries: QueryPoints<'_>,
        packed: bool,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Option<Image>> {
        let mut image = match (&self.built, &self.estimate) {
            (Some(built), Some(estimate)) => {
                let run = EstimateRun {
                    scene: f.scene,
                    textures: f.textures,
                    direct: f.direct,
                    queries,
                    packed,
                    map: &built.map,
                    estimate,
                    options: gi,
                    at: f.at,
                };
                let (img, stats) = run.estimate(timings, observer)?;
                self.estimates.push(stats);
                img
            }
            _ if packed => None,
            _ => Some(f.direct.read_radiance()),
        };
        if let (Some(global), Some(gather)) = (&self.global_map, &self.gather) {
            let run = GatherRun {
                scene: f.scene,
                textures: f.textures,
                direct: f.direct,
                queries,
                global: &global.map,
                gather,
                options: gi,
                at: f.at,
            };
            self.gathers.push(run.gather(f.seed, timings, observer)?);
            if let Some(image) = &mut image {
                image.add(&gather.read_indirect());
            }
        }
        if let (Some(vpls), Some(igi)) = (&self.vpls, &self.igi) {
            let at = f.at;
            let eye = f.camera_position;
            let stats = igi.run(
                f.textures,
                f.direct,
                vpls,
                eye,
                timings,
                &mut |done, total| {
                    observer.progress(&Progress::at("VPL gather", done as u64, total as u64, at))
                },
            )?;
            self.igi_stats.push(stats);
            if let Some(image) = &mut image {
                image.add(&igi.read_indirect());
            }
        }
        if let Some((r, _)) = &self.radiosity {
            r.run(f.textures, f.direct, timings)?;
            if let Some(image) = &mut image {
                image.add(&r.read_indirect());
            }
        }
        if let Some(run) = &mut self.differentials {
            run.ensure_map(f, timings)?;
            let map = run.map.as_ref().expect("ensure_map made it");
            let at = f.at;
            let stats =
                run.estimate
                    .run(f.textures, f.direct, map, timings, &mut |walking, hits| {
                        observer.progress(&Progress::at(
                            "footprint estimate",
                            hits - walking,
                            hits,
                            at,
                        ))
                    })?;
            self.footprint_stats.push(stats);
            if let Some(image) = &mut image {
                image.add(&run.estimate.read_indirect());
            }
        }
        Ok(image)
    }
}

/// Photon differentials' photons, when chosen (refusing other methods' options).
#[allow(clippy::too_many_arguments)]
fn differentials_run(
    gpu: &Gpu,
    scene: &Scene,
    textures: &SceneTextures,
    options: &RenderOptions,
    adaptive: bool,
    timings: &mut Timings,
    observer: &mut dyn RenderObserver,
) -> Result<Option<DifferentialsRun>> {
    let (w, h) = (options.width, options.height);
    Ok(
        match options
            .global
            .as_ref()
            .map(|g| (g, g.differentials.as_ref()))
        {
            Some((gi, Some(o))) => {
                if adaptive || gi.final_gather.is_some() || gi.igi.is_some() {
                    return Err(Error::InvalidOption(
                    "photon differentials replace the kNN estimate: drop --adaptive, --final-gather and IGI's options".into(),
                ));
                }
                observer.progress(&Progress::stage("photons", 0, 1));
                Some(DifferentialsRun::new(
                    gpu,
                    scene,
                    textures,
                    gi,
                    o,
                    (w, h, options.seed),
                    timings,
                )?)
            }
            _ => None,
        },
    )
}

/// The radiosity solution, when chosen (refusing other methods' options).
#[allow(clippy::too_many_arguments)]
fn radiosity_run(
    gpu: &Gpu,
    scene: &Scene,
    textures: &SceneTextures,
    options: &RenderOptions,
    adaptive: bool,
    timings: &mut Timings,
    observer: &mut dyn RenderObserver,
) -> Result<Option<(Radiosity, RadiosityReport)>> {
    let (w, h) = (options.width, options.height);
    Ok(
        match options.global.as_ref().map(|g| (g, g.radiosity.as_ref())) {
            Some((gi, Some(o))) => {
                if adaptive
                    || gi.final_gather.is_some()
                    || gi.igi.is_some()
                    || gi.differentials.is_some()
                {
                    return Err(Error::InvalidOption(
                    "radiosity computes the diffuse interreflection itself: drop --adaptive, --final-gather and the other methods' options".into(),
                ));
                }
                let mut r = Radiosity::new(gpu, scene, w, h, o)?;
                let report = r.solve(scene, textures, timings, &mut |shot, unshot| {
                    observer.progress(&Progress::stage(
                        "radiosity",
                        ((1.0 - unshot) * 1000.0) as u64,
                        1000,
                    ));
                    let _ = shot;
                })?;
                Some((r, report))
            }
            _ => None,
        },
    )
}

/// Refuses what no render can do before any GPU work.
fn check_request(gpu: &Gpu, options: &RenderOptions, cameras: &[Camera]) -> Result<()> {
    if cameras.is_empty() {
        return Err(Error::InvalidOption("no camera to render from".into()));
    }
    let max = gpu.max_texture_size();
    if options.width == 0 || options.height == 0 || options.width > max || options.height > max {
        return Err(Error::InvalidOption(format!(
            "image of {} x {} pixels: each side must be 1..={max} on this driver",
            options.width, options.height
        )));
    }
    Ok(())
}

fn finish(
    image: Image,
    timings: Timings,
    plan: PassPlan,
    built: Option<BuiltMap>,
    estimates: Vec<EstimateStats>,
    options: &RenderOptions,
    mut state: RenderState,
) -> RenderOutput {
    let passes = timings.stages.iter().map(|s| s.passes).sum();
    let photons = built.map(|b| {
        let report = report_of(&b, options);
        state.map = Some(b.map);
        report
    });
    RenderOutput {
        image,
        state,
        timings,
        passes,
        plan,
        photons,
        gather_photons: None,
        gathers: Vec::new(),
        adaptive: Vec::new(),
        vpls: None,
        igi: Vec::new(),
        differentials: None,
        footprint_estimates: Vec::new(),
        radiosity: None,
        estimate: estimates.last().cloned(),
        estimates,
    }
}

/// The photon stage's report of a built map.
fn report_of(b: &BuiltMap, options: &RenderOptions) -> PhotonReport {
    PhotonReport {
        trace: b.trace.clone(),
        frames_traced: b.frames_traced,
        grid: b.grid,
        grid_fitted: b.grid_fitted,
        build_stages: b.build_stages.clone(),
        config: options
            .global
            .as_ref()
            .map(|g| g.photons.clone())
            .unwrap_or_default(),
    }
}

/// The maps of a render: the one visualised at the first hits, and final
/// gather's global map. Under final gather the first is the caustic map, and
/// a scene with nothing specular has none.
fn build_maps(
    gpu: &Gpu,
    scene: &Scene,
    textures: &SceneTextures,
    gi: &GlobalIllumination,
    seed: u32,
    timings: &mut Timings,
) -> Result<(Option<BuiltMap>, Option<BuiltMap>)> {
    if gi.differentials.is_some() {
        // Photon differentials trace their own photons (DifferentialsRun).
        return Ok((None, None));
    }
    if gi.igi.is_some() || gi.radiosity.is_some() {
        // IGI's VPLs (radiosity's elements) carry the diffuse interreflection; the photon map only
        // the caustics, which VPLs cannot (light through glass or off a mirror
        // onto the first hit), and none in a scene with nothing specular.
        if !scene.has_specular() {
            return Ok((None, None));
        }
        let mut caustic = scene.clone();
        caustic.photon_map.caustics_only = true;
        caustic.photon_map.store_direct = false;
        let map = photon::build_map(gpu, &caustic, textures, &gi.photons, seed, timings)?;
        return Ok((Some(map), None));
    }
    if gi.final_gather.is_none() {
        let map = photon::build_map(gpu, scene, textures, &gi.photons, seed, timings)?;
        return Ok((Some(map), None));
    }
    let (caustic, global) = final_gather::map_scenes(scene)?;
    let caustic = if scene.has_specular() {
        Some(photon::build_map(
            gpu,
            &caustic,
            textures,
            &gi.photons,
            seed,
            timings,
        )?)
    } else {
        None
    };
    // Another seed: the two maps' photons are independent.
    let global_seed = crate::random::pcg_hash(seed ^ crate::layout::GATHER_STREAM);
    let global = photon::build_map(gpu, &global, textures, &gi.photons, global_seed, timings)?;
    Ok((caustic, Some(global)))
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
    options: &'a GlobalIllumination,
    at: At,
}

impl GatherRun<'_> {
    fn gather(
        &self,
        seed: u32,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<GatherStats> {
        let fg = self
            .options
            .final_gather
            .as_ref()
            .expect("a gather run has final-gather options");
        let estimate = EstimateOptions {
            leak: fg.leak,
            ..self.options.estimate_options()
        };
        let at = self.at;
        self.gather.run(
            self.textures,
            self.direct,
            self.queries,
            self.global,
            fg,
            &estimate,
            self.scene.photon_map.max_radius,
            self.scene.render.max_specular_depth,
            seed,
            timings,
            &mut |done, total| {
                observer.progress(&Progress::at("final gather", done as u64, total as u64, at))
            },
        )
    }
}

/// Where in the frame a pass is: view and eye sample.
#[derive(Clone, Copy, Debug)]
pub struct At {
    pub view: usize,
    pub views: usize,
    pub sample: u32,
    pub samples: u32,
}

/// One eye sample of one view.
pub struct EyeSample<'a> {
    pub camera: &'a Camera,
    pub sample: u32,
    pub seed: u32,
}

/// The ray tracer's passes for one eye sample: eye rays, then per specular
/// depth the closest hits, shadow rays and the specular continuation. Each
/// pass is timed by timer query and by wall clock (glFinish on both sides).
#[allow(clippy::too_many_arguments)]
pub fn trace_eye_paths(
    gpu: &Gpu,
    plan: &PassPlan,
    textures: &SceneTextures,
    tracer: &RayTracer,
    direct: &DirectLight,
    eye: &EyeSample<'_>,
    timings: &mut Timings,
    observer: &mut dyn RenderObserver,
    at: At,
) -> Result<()> {
    let total = plan.passes_per_sample() as u64;
    let query = crate::gpu::Query::timer(gpu)?;
    let mut done = 0u64;
    direct.clear();
    gpu.finish();
    let mut stage_wall = std::time::Instant::now();
    let mut timed = |name: &str, pass: &dyn Fn() -> Result<()>| -> Result<()> {
        query.begin();
        let result = pass();
        query.end();
        result?;
        gpu.finish();
        timings.add_both(name, query.seconds(), stage_wall.elapsed().as_secs_f64(), 1);
        stage_wall = std::time::Instant::now();
        done += 1;
        observer.progress(&Progress::at("ray tracing", done, total, at));
        Ok(())
    };
    if plan.fused {
        timed("eye paths (fused)", &|| {
            tracer.eye_paths_fused(textures, direct, eye.camera, plan, eye.sample, eye.seed)
        })?;
        return gpu.check("ray tracing");
    }
    timed("eye rays", &|| {
        tracer.eye_rays(eye.camera, plan, eye.sample, eye.seed)
    })?;
    for depth in 0..plan.depths {
        timed("intersect", &|| tracer.intersect(textures))?;
        for b in 0..plan.direct_passes {
            let samples = plan.shadow_batch(b);
            timed("shadow rays", &|| {
                direct.shade(
                    textures,
                    &tracer.hits,
                    plan,
                    samples.clone(),
                    depth,
                    eye.seed,
                )
            })?;
        }
        if depth + 1 < plan.depths {
            timed("specular", &|| tracer.specular(textures, depth, eye.seed))?;
        }
    }
    gpu.check("ray tracing")
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
    options: &'a GlobalIllumination,
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
        let (k, max_radius) = (self.scene.photon_map.k, self.scene.photon_map.max_radius);
        let options = self.options.estimate_options();
        let compose = || {
            self.estimate
                .compose(self.textures, self.direct, k, max_radius, true, true)
        };
        let mut observed = 0.0;
        let mut failure = None;
        let stats = self.estimate.run(
            self.textures,
            self.map,
            self.queries,
            k,
            max_radius,
            &options,
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

/// The running sum of eye samples (in order, then one division: the box filter).
#[derive(Default)]
struct ImageSum {
    sum: Option<Image>,
    count: u32,
}

impl ImageSum {
    fn add(&mut self, image: &Image) {
        self.count += 1;
        match &mut self.sum {
            None => self.sum = Some(image.clone()),
            Some(acc) => acc.add(image),
        }
    }

    fn mean(self) -> Image {
        let mut image = self.sum.expect("at least one sample");
        if self.count > 1 {
            image.divide(self.count as f32);
        }
        image
    }
}
