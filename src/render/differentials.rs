//! Photon differentials with a BVH photon map (Fabianowski and Dingliana
//! 2009) as a third method beside photon mapping and IGI, on the same passes
//! (`--method differentials`):
//!
//! 1. **Photons** are traced by the photon passes as for the kNN map (the
//!    scene's stored count, projection maps where it stores caustics only),
//!    and `photon::differentials` gives each record its differentials, its
//!    footprint and the footprint BVH.
//! 2. **The estimate** at each eye path's first diffuse hit sums every
//!    footprint that holds it (`footprint_gather`: a stackless walk of the
//!    implicit BVH, a bounded number of nodes a pass, ended by occlusion
//!    query), with a constant or Epanechnikov kernel; no k nearest are
//!    searched for.
//! 3. **The image**: direct light and specular paths from the ray tracer, plus
//!    throughput x albedo / pi x the footprints' irradiance.
//!
//! The smoothing factor s of diffusely reflected photons is the user's or
//! (`auto`) chosen to aim the mean number of footprints holding a first hit
//! (the paper's k_PD) at the scene's k, the kNN estimate's photon count: the
//! paper finds k_PM ~ k_PD gives equal quality. A pilot map built with s = 1
//! measures, over the first eye sample's hits, the mean count of caustic
//! footprints (which s does not scale) and of diffuse ones; s =
//! sqrt((k - caustic) / diffuse), since footprint areas grow as s^2. Where
//! the caustic ones alone reach k, s aims the diffuse ones at one a hit.
//! Clamping to r_max breaks the s^2 law, so the k_PD reached is reported and
//! may fall short of k.

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture};
use crate::layout::FOOTPRINT_BUDGET;
use crate::photon::differentials::{
    trace_differentials, DifferentialFrames, FootprintBuilder, FootprintMap, FootprintOptions,
    FootprintShape,
};
use crate::photon::{PhotonFrames, PhotonTracer, TraceReport};
use crate::scene::defaults::MAX_PHOTONS_STORED;
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;

use super::observer::{Progress, RenderObserver};
use super::photon_options::WithPhotons;
use super::sample::{FrameMethod, Prepare, SampleFrame};
use super::{DirectLight, Image, Timings};

/// The density-estimation kernel over a footprint's ellipse.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Kernel {
    /// 1 / A inside (the paper's main results).
    #[default]
    Constant,
    /// 2 (1 - u^2) / A (the paper's figure 4, right).
    Epanechnikov,
}

/// How `--method differentials` runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct DifferentialsOptions {
    /// s; None: chosen so that k_PD equals the scene's k (a pilot map).
    pub smoothing: Option<f32>,
    /// The factor of photons that have been only specular (the paper: 5).
    pub caustic_smoothing: f32,
    /// r_max (None: the scene's photon_map.max_radius).
    pub max_radius: Option<f32>,
    /// T (None: the paper's automatic threshold).
    pub leaf_size: Option<u32>,
    pub kernel: Kernel,
    /// Probes a footprint for its share on its own surface, so one that
    /// overhangs an edge keeps its power (0: the whole ellipse counts).
    pub coverage_samples: u32,
    /// Which query points a footprint holds: by default it follows a curved
    /// surface; the paper's ellipsoid loses light on one.
    pub footprint_shape: FootprintShape,
    /// Photons stored by a second trace aimed at mirrors and glass by
    /// projection maps, whose footprints carry the caustics (L S+ D) in place
    /// of the few the scene's own photons bring; 0: the paper's one map.
    /// None: the scene's stored count where its map stores more than
    /// caustics and it has a mirror or glass, else 0.
    pub caustic_photons: Option<u32>,
    /// Photon bounces at most, in place of the scene's photon_map.max_bounces:
    /// the paper scenes' 8 leave out about 3% of a Cornell box ceiling's
    /// light, which is all indirect. Russian roulette ends most far sooner.
    pub max_bounces: u32,
}

/// Photon bounces by default: as SPPM's and IGI's.
pub const MAX_BOUNCES: u32 = 32;

/// Coverage probes a footprint by default: enough that one probe is 1/16 of
/// the ellipse.
pub const COVERAGE_SAMPLES: u32 = 16;

impl Default for DifferentialsOptions {
    fn default() -> Self {
        Self {
            smoothing: None,
            caustic_smoothing: 5.0,
            max_radius: None,
            leaf_size: None,
            kernel: Kernel::Constant,
            coverage_samples: COVERAGE_SAMPLES,
            footprint_shape: FootprintShape::Curved,
            caustic_photons: None,
            max_bounces: MAX_BOUNCES,
        }
    }
}

impl DifferentialsOptions {
    pub fn check(&self) -> Result<()> {
        if let Some(s) = self.smoothing {
            Error::check_positive(
                "differentials.smoothing",
                s,
                "give a factor above 0, or auto",
            )?;
        }
        Error::check_positive(
            "differentials.caustic_smoothing",
            self.caustic_smoothing,
            "give a factor above 0",
        )?;
        if let Some(r) = self.max_radius {
            Error::check_positive("differentials.max_radius", r, "give a radius above 0")?;
        }
        if self.coverage_samples > 256 {
            return Err(Error::out_of_range(
                "differentials.coverage_samples",
                self.coverage_samples,
                "the allowed range is 0..=256 (0: no coverage probes)",
            ));
        }
        if let Some(n) = self.caustic_photons.filter(|&n| n > 0) {
            if !(64..=MAX_PHOTONS_STORED as u32).contains(&n) {
                return Err(Error::out_of_range(
                    "differentials.caustic_photons",
                    n,
                    format!("the allowed range is 64..={MAX_PHOTONS_STORED}, or 0 (no caustic footprint map), or auto"),
                ));
            }
        }
        Error::check_range("differentials.max_bounces", self.max_bounces, 1..=64)?;
        if let Some(t) = self.leaf_size {
            if !(1..=1024).contains(&t) {
                return Err(Error::out_of_range(
                    "differentials.leaf_size",
                    t,
                    "the allowed range is 1..=1024, or auto",
                ));
            }
        }
        Ok(())
    }

    /// The caustic footprint map's stored photons in `scene` (0: none).
    /// Asked for where the scene's map already holds only caustics, or where
    /// nothing is specular, it is refused.
    pub fn caustic_photons_in(&self, scene: &Scene) -> Result<u32> {
        let possible = scene.has_specular() && !scene.photon_map.caustics_only;
        match self.caustic_photons {
            None => Ok(if possible {
                scene.photon_map.photons_stored
            } else {
                0
            }),
            Some(0) => Ok(0),
            Some(n) if possible => Ok(n),
            Some(_) => Err(Error::InvalidOption(format!(
                "differentials.caustic_photons: {} {}; give 0 or auto",
                scene.name,
                if scene.photon_map.caustics_only {
                    "stores caustic photons only (caustics_only = true), already aimed by projection maps"
                } else {
                    "has no mirror or glass, so no caustic to aim photons at"
                }
            ))),
        }
    }

    pub fn footprint_options(&self, scene: &Scene, smoothing: f32) -> FootprintOptions {
        FootprintOptions {
            smoothing,
            caustic_smoothing: self.caustic_smoothing,
            max_radius: self.max_radius.unwrap_or(scene.photon_map.max_radius),
            leaf_size: self.leaf_size,
            coverage_samples: self.coverage_samples,
            coverage_epanechnikov: self.kernel == Kernel::Epanechnikov,
            drop_caustics: false,
            shape: self.footprint_shape,
        }
    }
}

/// The photons of a render with their differentials.
pub struct DifferentialPhotons {
    pub frames: PhotonFrames,
    pub differentials: DifferentialFrames,
    pub trace: TraceReport,
}

impl DifferentialPhotons {
    /// Their footprint map, its stages folded into `timings` as `stage`.
    fn footprint_map(
        &self,
        builder: &FootprintBuilder,
        f: &SampleFrame<'_>,
        options: &FootprintOptions,
        stage: &str,
        timings: &mut Timings,
    ) -> Result<FootprintMap> {
        let t0 = std::time::Instant::now();
        let mut stages = Timings::default();
        let map = builder.build(
            f.scene,
            f.textures,
            &self.frames,
            &self.differentials,
            options,
            &mut stages,
        )?;
        timings.add_folded(stage, &stages, t0);
        Ok(map)
    }

    /// Traces the scene's photons (to its stored count) and their differentials.
    pub fn trace(
        gpu: &Gpu,
        scene: &Scene,
        textures: &SceneTextures,
        tracer: &PhotonTracer,
        seed: u32,
        timings: &mut Timings,
    ) -> Result<Self> {
        let (frames, trace) =
            crate::photon::build::trace_timed(gpu, tracer, scene, textures, seed, timings)?;
        let t0 = std::time::Instant::now();
        let differentials = trace_differentials(gpu, scene, textures, &frames)?;
        gpu.finish();
        timings.add_since("photon differentials", 0.0, t0, frames.frames as usize);
        Ok(Self {
            frames,
            differentials,
            trace,
        })
    }
}

/// What one footprint estimate did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct FootprintStats {
    pub passes: u32,
    /// Pixels with a first diffuse hit.
    pub query_pixels: u64,
    /// Mean footprints holding a first hit (k_PD), and of them those of
    /// diffusely reflected photons.
    pub mean_footprints: f64,
    pub mean_diffuse_footprints: f64,
    /// Mean BVH nodes visited and footprints examined per first hit.
    pub mean_nodes: f64,
    pub mean_examined: f64,
    pub wall_seconds: f64,
}

/// The footprint estimate's textures and programs at one image size.
pub struct FootprintEstimate {
    gpu: Gpu,
    init: Program,
    gather: Program,
    compose: Program,
    kernel: Kernel,
    /// rgb: the footprints' irradiance, w: footprints holding the hit.
    pub sum: Texture,
    /// node (0: done), nodes visited, footprints examined, diffuse footprints.
    pub walk: Texture,
    state_target: Target,
    /// Reflected indirect light.
    pub indirect: Texture,
    indirect_target: Target,
    width: u32,
    height: u32,
}

impl FootprintEstimate {
    pub fn new(gpu: &Gpu, width: u32, height: u32, kernel: Kernel) -> Result<Self> {
        let sum = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let walk = Texture::new(gpu, width, height, TexFormat::Rgba32I)?;
        let indirect = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        Ok(Self {
            gpu: gpu.clone(),
            init: Program::fullscreen(gpu, "render/footprint_init.frag")?,
            gather: Program::fullscreen(gpu, "render/footprint_gather.frag")?,
            compose: Program::fullscreen(gpu, "render/footprint_compose.frag")?,
            kernel,
            state_target: Target::new(gpu, &[&sum, &walk])?,
            indirect_target: Target::new(gpu, &[&indirect])?,
            sum,
            walk,
            indirect,
            width,
            height,
        })
    }

    /// The estimate at `direct`'s first hits, composed into `indirect`. Adds
    /// "footprint estimate" to `timings`; `on_pass(still walking, hits)`.
    pub fn run(
        &self,
        textures: &SceneTextures,
        direct: &DirectLight,
        map: &FootprintMap,
        timings: &mut Timings,
        on_pass: &mut dyn FnMut(u64, u64),
    ) -> Result<FootprintStats> {
        let gpu = &self.gpu;
        gpu.finish();
        let t0 = std::time::Instant::now();
        let hits = Query::occlusion(gpu)?;
        self.init
            .bind()
            .texture("u_query_position", &direct.diffuse_position)
            .draw_fullscreen(&self.state_target, &DrawState::PLAIN)?;
        let mut stats = FootprintStats::default();
        loop {
            crate::interrupt::check()?;
            gpu.texture_barrier();
            let mut b = self.gather.bind();
            b.texture("u_query_position", &direct.diffuse_position)
                .texture("u_query_normal", &direct.diffuse_normal)
                .texture("u_state_sum", &self.sum)
                .texture("u_state_walk", &self.walk)
                .texture("u_box_min", &map.box_min)
                .texture("u_box_max", &map.box_max)
                .int("u_box_width", map.box_width as i32)
                .texture("u_footprint0", &map.footprints[0])
                .texture("u_footprint1", &map.footprints[1])
                .texture("u_footprint2", &map.footprints[2])
                .texture("u_footprint3", &map.footprints[3])
                .int("u_footprint_width", map.width as i32)
                .int("u_count", map.count as i32)
                .int("u_leaves", map.leaves as i32)
                .int("u_leaf_size", map.leaf_size as i32)
                .int("u_budget", FOOTPRINT_BUDGET as i32)
                .int(
                    "u_epanechnikov",
                    i32::from(self.kernel == Kernel::Epanechnikov),
                )
                .int("u_curved", i32::from(map.options.shape.curved()));
            hits.around(|| b.draw_fullscreen(&self.state_target, &DrawState::PLAIN))?;
            drop(b);
            // The fragments drawn are the pixels that were still walking.
            let walking = hits.count();
            if stats.passes == 0 {
                stats.query_pixels = walking;
            }
            if walking == 0 {
                break;
            }
            stats.passes += 1;
            on_pass(walking, stats.query_pixels);
        }
        gpu.texture_barrier();
        let mut b = self.compose.bind();
        textures.bind(&mut b);
        direct.bind_weights(&mut b);
        b.texture("u_state_sum", &self.sum)
            .draw_fullscreen(&self.indirect_target, &DrawState::PLAIN)?;
        drop(b);
        gpu.finish();
        stats.wall_seconds = t0.elapsed().as_secs_f64();
        timings.add_both(
            "footprint estimate",
            0.0,
            stats.wall_seconds,
            stats.passes as usize + 2,
        );
        gpu.check("footprint estimate")?;
        self.summarise(&mut stats);
        Ok(stats)
    }

    /// Means over the first hits, from a read-back of the state (not timed):
    /// a pixel with a hit visited at least the root.
    fn summarise(&self, stats: &mut FootprintStats) {
        let sum = self.sum.read_f32();
        let walk = self.walk.read_i32();
        let (mut n, mut k, mut kd, mut nodes, mut examined) = (0u64, 0f64, 0f64, 0f64, 0f64);
        for i in 0..(self.width * self.height) as usize {
            if walk[4 * i + 1] > 0 {
                n += 1;
                k += f64::from(sum[4 * i + 3]);
                nodes += f64::from(walk[4 * i + 1]);
                examined += f64::from(walk[4 * i + 2]);
                kd += f64::from(walk[4 * i + 3]);
            }
        }
        let n = n.max(1) as f64;
        stats.mean_footprints = k / n;
        stats.mean_diffuse_footprints = kd / n;
        stats.mean_nodes = nodes / n;
        stats.mean_examined = examined / n;
    }

    pub fn read_indirect(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.indirect.read_f32())
    }
}

/// The smoothing factor that aims the mean of all footprints holding a first
/// hit at `k`, from a pilot's means at s = 1 of all and of diffuse footprints
/// (only the diffuse ones grow, as s^2); at least one diffuse footprint a hit.
/// None when the pilot found no diffuse one (s then touches no footprint).
pub fn smoothing_for(k: u32, pilot_mean_all: f64, pilot_mean_diffuse: f64) -> Option<f32> {
    let caustic = (pilot_mean_all - pilot_mean_diffuse).max(0.0);
    let target = (k as f64 - caustic).max(1.0);
    (pilot_mean_diffuse > 0.0).then(|| (target / pilot_mean_diffuse).sqrt() as f32)
}

/// What the photon-differentials map was made of.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DifferentialsReport {
    pub trace: TraceReport,
    pub frames_traced: u32,
    pub footprints: u32,
    /// Footprints of photons reflected diffusely before (the others: caustics).
    pub diffuse_footprints: u32,
    pub degenerate_footprints: u32,
    /// The share of the stored power those carry (lost to the estimate).
    pub degenerate_power_fraction: f64,
    /// Caustic footprints of the scene's photons left out, and the caustic
    /// footprint map that carries their light instead.
    pub dropped_caustic_footprints: u32,
    pub caustic_map: Option<CausticFootprintsReport>,
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
    /// Coverage probes a footprint (0: the whole ellipse counts).
    pub coverage_samples: u32,
    /// Which query points a footprint held.
    pub footprint_shape: FootprintShape,
    pub total_footprint_area: f64,
    pub surface_area: f64,
    pub delta: f32,
}

/// The caustic footprint map: photons aimed at mirrors and glass by
/// projection maps, stored at their first diffuse hit after only specular
/// bounces (L S+ D), and each eye sample's estimate over their footprints.
pub struct CausticFootprints {
    pub photons: DifferentialPhotons,
    pub map: Option<FootprintMap>,
    pub stats: Vec<FootprintStats>,
}

impl CausticFootprints {
    /// Traces `stored` caustic photons of `scene`, on a seed of their own.
    fn trace(
        p: &Prepare<'_>,
        photon_scene: &Scene,
        tracer: &PhotonTracer,
        stored: u32,
        timings: &mut Timings,
    ) -> Result<Self> {
        let mut scene = photon_scene.clone();
        scene.photon_map.caustics_only = true;
        scene.photon_map.specular_last_only = false;
        scene.photon_map.store_direct = false;
        scene.photon_map.photons_stored = stored;
        // Not a seed the scene's own photons use for any render.
        let seed = p.seed.wrapping_mul(0x9E37_79B9).rotate_left(16) ^ 0x85EB_CA6B;
        let photons = DifferentialPhotons::trace(p.gpu, &scene, p.textures, tracer, seed, timings)?;
        Ok(Self {
            photons,
            map: None,
            stats: Vec::new(),
        })
    }

    pub fn report(&self) -> Option<CausticFootprintsReport> {
        let m = self.map.as_ref()?;
        Some(CausticFootprintsReport {
            trace: self.photons.trace.clone(),
            footprints: m.count,
            degenerate_footprints: m.degenerate,
            leaves: m.leaves,
            leaf_size: m.leaf_size,
            estimate_passes: self.stats.iter().map(|s| s.passes).sum(),
            mean_footprints: self.stats.first().map_or(0.0, |s| s.mean_footprints),
        })
    }
}

/// What the caustic footprint map was made of.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CausticFootprintsReport {
    pub trace: TraceReport,
    pub footprints: u32,
    pub degenerate_footprints: u32,
    pub leaves: u32,
    pub leaf_size: u32,
    /// Its estimate's walk passes over every eye sample, and the first
    /// sample's mean footprints holding a hit.
    pub estimate_passes: u32,
    pub mean_footprints: f64,
}

/// Photon differentials' GPU state: the photons, the map (made on the first
/// eye sample, after the pilot when s is automatic) and the estimate.
pub struct DifferentialsRun {
    pub photons: DifferentialPhotons,
    pub map: Option<FootprintMap>,
    /// The caustics' own map, when the scene's photons leave them out.
    pub caustic: Option<Box<CausticFootprints>>,
    pub estimate: FootprintEstimate,
    builder: FootprintBuilder,
    options: DifferentialsOptions,
    /// The pilot's mean footprints a hit: all, and diffuse.
    pilot_mean: Option<(f64, f64)>,
    /// Each eye sample's estimate.
    pub stats: Vec<FootprintStats>,
}

impl DifferentialsRun {
    /// Traces the photons with their differentials; the map waits for the
    /// first eye sample's hits.
    pub fn prepare(
        p: &Prepare<'_>,
        with: &WithPhotons<DifferentialsOptions>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let (gpu, o) = (p.gpu, &with.method);
        let (w, h) = (p.width, p.height);
        observer.progress(&Progress::stage("photons", 0, 1));
        o.check()?;
        let tracer = PhotonTracer::with_config(gpu, with.photons.trace())?;
        let scene = p.scene.with_max_bounces(o.max_bounces);
        let photons =
            DifferentialPhotons::trace(gpu, &scene, p.textures, &tracer, p.seed, timings)?;
        let caustic = match o.caustic_photons_in(p.scene)? {
            0 => None,
            n => Some(Box::new(CausticFootprints::trace(
                p, &scene, &tracer, n, timings,
            )?)),
        };
        Ok(Self {
            photons,
            map: None,
            caustic,
            estimate: FootprintEstimate::new(gpu, w, h, o.kernel)?,
            builder: FootprintBuilder::new(gpu)?,
            options: o.clone(),
            pilot_mean: None,
            stats: Vec::new(),
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
                    let options = self.footprint_options(f.scene, 1.0);
                    let pilot = self.builder.build(
                        f.scene,
                        f.textures,
                        &self.photons.frames,
                        &self.photons.differentials,
                        &options,
                        &mut pilot_timings,
                    )?;
                    if pilot.diffuse == 0 {
                        // Caustics only: s touches no footprint, the pilot is the map.
                        timings.add_folded("footprint map", &pilot_timings, t0);
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
                    timings.add_since("smoothing pilot", 0.0, t0, pilot_timings.passes_total());
                    self.pilot_mean = Some((stats.mean_footprints, stats.mean_diffuse_footprints));
                    smoothing_for(
                        f.scene.photon_map.k,
                        stats.mean_footprints,
                        stats.mean_diffuse_footprints,
                    )
                    .unwrap_or(1.0)
                }
            };
            let options = self.footprint_options(f.scene, smoothing);
            let map =
                self.photons
                    .footprint_map(&self.builder, f, &options, "footprint map", timings)?;
            self.map = Some(map);
        }
        if let Some(c) = self.caustic.as_mut().filter(|c| c.map.is_none()) {
            // Only caustic footprints: s touches none of them.
            let options = self.options.footprint_options(f.scene, 1.0);
            let map = c.photons.footprint_map(
                &self.builder,
                f,
                &options,
                "caustic footprint map",
                timings,
            )?;
            c.map = Some(map);
        }
        Ok(())
    }

    /// The footprint options at `smoothing`, leaving the scene's caustic
    /// footprints out when the caustic map carries them.
    fn footprint_options(&self, scene: &Scene, smoothing: f32) -> FootprintOptions {
        FootprintOptions {
            drop_caustics: self.caustic.is_some(),
            ..self.options.footprint_options(scene, smoothing)
        }
    }

    pub fn report(&self) -> Option<DifferentialsReport> {
        let m = self.map.as_ref()?;
        Some(DifferentialsReport {
            trace: self.photons.trace.clone(),
            frames_traced: self.photons.frames.frames,
            footprints: m.count,
            diffuse_footprints: m.diffuse,
            degenerate_footprints: m.degenerate,
            degenerate_power_fraction: m.degenerate_power_fraction,
            dropped_caustic_footprints: m.dropped_caustics,
            caustic_map: self.caustic.as_deref().and_then(CausticFootprints::report),
            smoothing: m.options.smoothing,
            pilot_mean_footprints: self.pilot_mean.map(|m| m.0),
            pilot_mean_diffuse_footprints: self.pilot_mean.map(|m| m.1),
            caustic_smoothing: m.options.caustic_smoothing,
            max_radius: m.options.max_radius,
            kernel: self.options.kernel,
            leaf_size: m.leaf_size,
            auto_leaf_size: m.auto_leaf_size,
            leaves: m.leaves,
            coverage_samples: m.options.coverage_samples,
            footprint_shape: m.options.shape,
            total_footprint_area: m.total_area,
            surface_area: m.surface_area,
            delta: m.delta,
        })
    }
}

impl FrameMethod for DifferentialsRun {
    /// The direct light plus the footprints' light at the first hits.
    fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        let mut image = f.direct.read_radiance();
        self.ensure_map(f, timings)?;
        let map = self.map.as_ref().expect("ensure_map made it");
        let estimate = &mut self.estimate;
        let mut walk = |map: &FootprintMap,
                        stage: &'static str,
                        timings: &mut Timings|
         -> Result<FootprintStats> {
            let stats =
                estimate.run(f.textures, f.direct, map, timings, &mut |walking, hits| {
                    observer.progress(&Progress::at(stage, hits - walking, hits, f.at))
                })?;
            image.add(&estimate.read_indirect());
            Ok(stats)
        };
        self.stats.push(walk(map, "footprint estimate", timings)?);
        if let Some(c) = self.caustic.as_mut() {
            let map = c.map.as_ref().expect("ensure_map made it");
            c.stats
                .push(walk(map, "caustic footprint estimate", timings)?);
        }
        Ok(image)
    }
}
