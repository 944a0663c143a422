//! Figure 1's "ray trace scene" box (and, later, "radiance estimate"): eye rays,
//! hit textures per specular depth, shadow rays, reflection and refraction.

pub mod direct;
pub mod image;
pub mod radiance_estimate;
pub mod ray_trace;
pub mod timing;

use crate::gpu::{Gpu, GpuError, TimerQuery};
use crate::photon::{
    BitonicBuild, BuildMethod, PhotonMap, PhotonTracer, RandomSource, StencilRouting, VertexFeed,
};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;

pub use self::image::Image;
pub use direct::DirectLight;
pub use radiance_estimate::{EstimateMode, EstimateOptions, EstimateStats, RadianceEstimate};
pub use ray_trace::{HitBuffers, RayBuffers, RayTracer};
pub use timing::{StageTiming, Timings};

/// How one render runs (what the scene file does not fix).
#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub seed: u32,
    pub width: u32,
    pub height: u32,
    /// Shadow samples per area light drawn in one pass (bounds work per pass).
    pub shadow_batch: u32,
    /// Eye samples per pixel: 1 (the paper) shoots through the pixel centre;
    /// more are stratified, jittered and box-filtered.
    pub spp: u32,
    /// Photon map and radiance estimate; None draws direct light and specular paths only.
    pub global: Option<GlobalIllumination>,
}

/// The photon-mapping half of a render.
#[derive(Clone, Debug)]
pub struct GlobalIllumination {
    pub build: BuildMethod,
    pub stencil_block: u32,
    pub feed: VertexFeed,
    /// The paper's 2003 constraints: random-number texture, read-back before routing.
    pub faithful: bool,
    pub estimate: EstimateOptions,
    pub snapshots: Option<Snapshots>,
    /// Trace every bounce up to max_bounces even when no photon is left alive.
    pub all_bounces: bool,
    /// Aim photons by projection maps when the scene stores caustics only.
    pub projection_maps: bool,
}

impl Default for GlobalIllumination {
    fn default() -> Self {
        Self {
            build: BuildMethod::Bitonic,
            stencil_block: 4,
            feed: VertexFeed::VertexFetch,
            faithful: false,
            estimate: EstimateOptions::default(),
            snapshots: None,
            all_bounces: false,
            projection_maps: true,
        }
    }
}

/// Running images of the radiance estimate (section 3.4, figure 8).
#[derive(Clone, Debug)]
pub struct Snapshots {
    pub dir: std::path::PathBuf,
    pub every: SnapshotEvery,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SnapshotEvery {
    Seconds(f64),
    Passes(u32),
}

impl RenderOptions {
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            seed: 1,
            width: scene.camera.width,
            height: scene.camera.height,
            shadow_batch: 8,
            spp: 1,
            global: Some(GlobalIllumination::default()),
        }
    }

    pub fn direct_only(mut self) -> Self {
        self.global = None;
        self
    }
}

/// One line of `--explain`: a stage's passes, run or skipped, and why.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ExplainLine {
    pub stage: String,
    pub passes: usize,
    pub ran: bool,
    pub why: String,
}

/// A snapshot written during the estimate.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SnapshotRecord {
    pub file: String,
    pub pass: u32,
    /// Seconds of radiance estimate so far (writing snapshots not counted).
    pub seconds: f64,
    pub searching_pixels: u64,
}

/// What a render leaves behind.
pub struct RenderOutput {
    pub image: Image,
    /// The GPU state behind the image, for tests and the software reference.
    pub state: RenderState,
    pub timings: Timings,
    pub passes: usize,
    pub photons: Option<crate::photon::TraceReport>,
    pub estimate: Option<EstimateStats>,
    pub snapshots: Vec<SnapshotRecord>,
    pub explain: Vec<ExplainLine>,
}

/// The GPU resources of a finished render.
pub struct RenderState {
    pub textures: SceneTextures,
    /// Direct light and each eye path's first diffuse hit.
    pub direct: DirectLight,
    pub map: Option<PhotonMap>,
    pub estimate: Option<RadianceEstimate>,
}

/// Something that wants to hear about progress: (stage, done, total).
pub type Progress<'a> = &'a dyn Fn(&str, u64, u64);

/// The ray tracer's passes for a scene, derived once from it and the options.
struct PassPlan {
    specular: bool,
    has_area: bool,
    /// Intersect passes per eye sample: one per specular depth.
    depths: u32,
    /// Shadow-ray passes per depth: batches of area-light samples, or one.
    direct_passes: u32,
}

impl PassPlan {
    fn new(scene: &Scene, options: &RenderOptions) -> Self {
        let specular = scene.has_specular();
        let has_area = scene
            .lights
            .iter()
            .any(|l| matches!(l, crate::scene::Light::Area { .. }));
        Self {
            specular,
            has_area,
            // With nothing specular, an eye path ends at its first hit.
            depths: if specular {
                scene.render.max_specular_depth + 1
            } else {
                1
            },
            direct_passes: if has_area {
                scene
                    .render
                    .shadow_rays
                    .div_ceil(options.shadow_batch.max(1))
            } else {
                1
            },
        }
    }
}

/// The seed of eye sample `sample`: the render's own for sample 0 (so one
/// sample per pixel is exactly the paper's render), a hash of it for the rest.
pub fn sample_seed(seed: u32, sample: u32) -> u32 {
    use crate::reference::random::pcg_hash;
    if sample == 0 {
        seed
    } else {
        pcg_hash(seed ^ pcg_hash(sample.wrapping_add(0x5bd1e995)))
    }
}

/// The ray tracer's passes for one eye sample: eye rays, then per specular
/// depth the closest hits, shadow rays and the specular continuation.
#[allow(clippy::too_many_arguments)]
fn trace_eye_paths(
    gpu: &Gpu,
    scene: &Scene,
    camera: &crate::scene::Camera,
    textures: &SceneTextures,
    tracer: &RayTracer,
    direct: &DirectLight,
    options: &RenderOptions,
    sample: u32,
    timings: &mut Timings,
    progress: Progress<'_>,
) -> Result<(), GpuError> {
    let seed = sample_seed(options.seed, sample);
    let PassPlan {
        depths,
        direct_passes,
        ..
    } = PassPlan::new(scene, options);
    let total = (1 + depths as usize * (1 + direct_passes as usize) + (depths as usize - 1)) as u64;
    let query = TimerQuery::new(gpu)?;
    let mut done = 0u64;
    // Each pass: GPU time by timer query, wall time with glFinish on both sides.
    direct.clear();
    gpu.finish();
    let mut stage_wall = std::time::Instant::now();
    let mut tick = |timings: &mut Timings, name: &str, q: &TimerQuery| {
        gpu.finish();
        timings.add_both(name, q.seconds(), stage_wall.elapsed().as_secs_f64(), 1);
        stage_wall = std::time::Instant::now();
        done += 1;
        progress("ray tracing", done, total);
    };
    query.begin();
    tracer.eye_rays(camera, options, sample, seed);
    query.end();
    tick(timings, "eye rays", &query);
    for depth in 0..depths {
        query.begin();
        tracer.intersect(textures);
        query.end();
        tick(timings, "intersect", &query);
        for b in 0..direct_passes {
            let begin = b * options.shadow_batch;
            let end = ((b + 1) * options.shadow_batch).min(scene.render.shadow_rays);
            query.begin();
            direct.shade(
                textures,
                &tracer.hits,
                scene.render.shadow_rays,
                begin..end,
                depth,
                seed,
            );
            query.end();
            tick(timings, "shadow rays", &query);
        }
        if depth + 1 < depths {
            query.begin();
            tracer.specular(textures, depth, seed);
            query.end();
            tick(timings, "specular", &query);
        }
    }
    gpu.check("ray tracing")
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
    progress: Progress<'_>,
) -> Result<RenderOutput, GpuError> {
    render_views(
        gpu,
        scene,
        options,
        std::slice::from_ref(&scene.camera),
        progress,
        &mut |_, _| Ok(()),
    )
}

/// Renders the scene from each camera in turn on one photon map (the paper's
/// figure 1: photons are traced and the map built only when geometry or lights
/// change). `on_frame` receives each view's image; the output holds the last.
pub fn render_views(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    cameras: &[crate::scene::Camera],
    progress: Progress<'_>,
    on_frame: &mut dyn FnMut(usize, &Image) -> Result<(), String>,
) -> Result<RenderOutput, GpuError> {
    if cameras.is_empty() {
        return Err(GpuError::Gl("no camera to render from".into()));
    }
    let max = crate::gpu::max_texture_size(gpu);
    if options.width > max || options.height > max {
        return Err(GpuError::Gl(format!(
            "image of {} x {} pixels: each side must be 1..={max} on this driver",
            options.width, options.height
        )));
    }
    let spp = options.spp.max(1);
    let textures = SceneTextures::new(gpu, scene)?;
    let tracer = RayTracer::new(gpu, options.width, options.height)?;
    let direct = DirectLight::new(gpu, options.width, options.height)?;
    let mut timings = Timings::default();
    let wall = std::time::Instant::now();

    let PassPlan {
        specular,
        has_area,
        depths,
        direct_passes,
    } = PassPlan::new(scene, options);
    let mut explain = vec![
        ExplainLine {
            stage: "eye rays".into(),
            passes: spp as usize,
            ran: true,
            why: if spp == 1 {
                "one ray per pixel centre".into()
            } else {
                format!("{spp} stratified, jittered samples per pixel, one pass each")
            },
        },
        ExplainLine {
            stage: "intersect".into(),
            passes: (depths * spp) as usize,
            ran: true,
            why: if specular {
                format!(
                    "one per specular depth 0..={} per sample",
                    scene.render.max_specular_depth
                )
            } else {
                "depth 0 only: the scene has no mirror or glass".into()
            },
        },
        ExplainLine {
            stage: "shadow rays".into(),
            passes: (depths * direct_passes * spp) as usize,
            ran: true,
            why: if has_area {
                format!(
                    "{} samples per area light in batches of {} at each depth",
                    scene.render.shadow_rays, options.shadow_batch
                )
            } else {
                "one ray per point light at each depth".into()
            },
        },
        ExplainLine {
            stage: "specular".into(),
            passes: ((depths - 1) * spp) as usize,
            ran: specular,
            why: if specular {
                "reflect or refract at mirror and glass hits".into()
            } else {
                "skipped: no specular surface".into()
            },
        },
    ];

    // Photons first: one map serves every eye sample.
    let mut photon_report = None;
    let map = match &options.global {
        None => {
            explain.push(ExplainLine {
                stage: "photons, map, estimate".into(),
                passes: 0,
                ran: false,
                why: "skipped: direct light only".into(),
            });
            None
        }
        Some(gi) => {
            let random = if gi.faithful {
                RandomSource::Texture
            } else {
                RandomSource::Hash
            };
            let mut photon_tracer = PhotonTracer::with_random(gpu, random)?;
            photon_tracer.stop_when_dead = !gi.all_bounces;
            photon_tracer.projection_maps = gi.projection_maps;
            progress("photons", 0, 1);
            gpu.finish();
            let t0 = std::time::Instant::now();
            let (frames, report) = photon_tracer.trace_to_stored(scene, &textures, options.seed)?;
            gpu.finish();
            // Wall time covers every attempt at the stored count.
            timings.add_both(
                "trace photons",
                report.gpu_seconds,
                t0.elapsed().as_secs_f64(),
                frames.frames as usize,
            );
            explain.push(ExplainLine {
                stage: "trace photons".into(),
                passes: frames.frames as usize,
                ran: true,
                                why: format!(
                    "emission + {} bounces{}; {} photons traced ({} attempts), the first {} kept: {} stored",
                    frames.frames - 1,
                    if frames.frames < scene.photon_map.max_bounces + 1 {
                        format!(" (stopped: no photon alive; {} more skipped)", scene.photon_map.max_bounces + 1 - frames.frames)
                    } else {
                        String::new()
                    },
                    report.emitted,
                    report.attempts.len(),
                    report.photons_used,
                    report.stored
                ),
            });
            explain.push(ExplainLine {
                stage: "projection maps".into(),
                passes: 0,
                ran: report.projection.is_some(),
                why: match (&report.projection, scene.photon_map.caustics_only) {
                    (Some(p), _) => format!(
                        "caustics only: photons leave through {} of {} emission cells ({}x{} a light) that can reach a mirror or glass shape, {:.2}% of the lights' power",
                        p.kept_cells,
                        p.cells,
                        p.resolution,
                        p.resolution,
                        100.0 * p.kept_power_fraction
                    ),
                    (None, true) => "skipped: switched off (--no-projection-map); photons leave in every direction and only caustic paths are stored".into(),
                    (None, false) => "skipped: the map stores indirect diffuse light too, which any emitted direction may carry (caustics_only = true aims photons at specular shapes)".into(),
                },
            });
            // The scene's grid bounds, or (when it fixes none) the box of the photons.
            let grid = crate::photon::fit::grid_for(gpu, scene, &frames)?;
            explain.push(ExplainLine {
                stage: "grid bounds".into(),
                passes: 0,
                ran: true,
                why: format!(
                    "{:?} cells over {:?}..{:?}, {}",
                    grid.resolution,
                    grid.min.to_array(),
                    grid.max.to_array(),
                    if scene.photon_map.grid_bounds.is_some() {
                        "as the scene fixes them"
                    } else {
                        "fitted to the stored photons"
                    }
                ),
            });
            let mut build_timings = Timings::default();
            let feed = if gi.faithful {
                VertexFeed::Readback
            } else {
                gi.feed
            };
            let t0 = std::time::Instant::now();
            let map = match gi.build {
                BuildMethod::Bitonic => {
                    let bitonic = BitonicBuild::with_addressing(gpu, gi.faithful)?;
                    PhotonMap::Sorted(bitonic.build(&frames, &grid, &mut build_timings)?)
                }
                BuildMethod::Stencil => PhotonMap::Routed(StencilRouting::new(gpu)?.build(
                    &frames,
                    &grid,
                    gi.stencil_block,
                    feed,
                    &mut build_timings,
                )?),
            };
            gpu.finish();
            for st in &build_timings.stages {
                explain.push(ExplainLine {
                    stage: format!("build map: {}", st.name),
                    passes: st.passes,
                    ran: true,
                    why: format!("{:?} build", gi.build),
                });
            }
            let build_passes = build_timings.stages.iter().map(|s| s.passes).sum();
            timings.add_both(
                "build map",
                build_timings.gpu_total(),
                t0.elapsed().as_secs_f64(),
                build_passes,
            );
            photon_report = Some(report);
            Some(map)
        }
    };
    let estimate = match &map {
        Some(_) => Some(RadianceEstimate::new(gpu, options.width, options.height)?),
        None => None,
    };

    let mut snapshots = Vec::new();
    let mut stats = None;
    let mut last_image = None;
    for (view, camera) in cameras.iter().enumerate() {
        let mut sum: Option<Image> = None;
        for sample in 0..spp {
            trace_eye_paths(
                gpu,
                scene,
                camera,
                &textures,
                &tracer,
                &direct,
                options,
                sample,
                &mut timings,
                progress,
            )?;
            let image = match (&options.global, &map, &estimate) {
                (Some(gi), Some(map), Some(estimate)) => {
                    let (k, max_radius) = (scene.photon_map.k, scene.photon_map.max_radius);
                    let mut snapshot_seconds = 0.0;
                    let mut last_snapshot = (0u32, 0.0f64);
                    let mut snapshot_error = None;
                    let estimate_options = EstimateOptions {
                        float_addressing: gi.faithful,
                        ..gi.estimate.clone()
                    };
                    let snap_config = if sample == 0 && view == 0 {
                        gi.snapshots.as_ref()
                    } else {
                        None
                    };
                    let s =
                        estimate.run(map, &direct, k, max_radius, &estimate_options, &mut |r| {
                            progress(
                                "radiance estimate",
                                r.query_pixels - r.searching,
                                r.query_pixels,
                            );
                            let Some(snap) = snap_config else { return };
                            let seconds = r.elapsed_seconds - snapshot_seconds;
                            let due = match snap.every {
                                SnapshotEvery::Passes(n) => {
                                    r.pass == 0 || r.pass >= last_snapshot.0 + n.max(1)
                                }
                                SnapshotEvery::Seconds(s) => {
                                    r.pass == 0 || seconds >= last_snapshot.1 + s
                                }
                            };
                            if !due || snapshot_error.is_some() {
                                return;
                            }
                            let t0 = std::time::Instant::now();
                            let img = r
                                .estimate
                                .compose(&textures, &direct, k, max_radius, true, true);
                            let file = format!("snapshot_{:04}.png", snapshots.len());
                            match img
                                .png_bytes()
                                .and_then(|b| image::write_atomically(&snap.dir.join(&file), &b))
                            {
                                Ok(()) => snapshots.push(SnapshotRecord {
                                    file,
                                    pass: r.pass,
                                    seconds,
                                    searching_pixels: r.searching,
                                }),
                                Err(e) => snapshot_error = Some(e),
                            }
                            last_snapshot = (r.pass, seconds);
                            snapshot_seconds += t0.elapsed().as_secs_f64();
                        })?;
                    if let Some(e) = snapshot_error {
                        return Err(GpuError::Gl(format!("writing a snapshot: {e}")));
                    }
                    timings.add_both(
                        "radiance estimate",
                        s.gpu_seconds,
                        s.wall_seconds - snapshot_seconds,
                        s.passes as usize,
                    );
                    let image = estimate.compose(&textures, &direct, k, max_radius, true, true);
                    if let Some(snap) = snap_config {
                        let final_file = format!("snapshot_{:04}.png", snapshots.len());
                        image
                            .png_bytes()
                            .and_then(|b| image::write_atomically(&snap.dir.join(&final_file), &b))
                            .map_err(GpuError::Gl)?;
                        snapshots.push(SnapshotRecord {
                            file: final_file,
                            pass: s.passes,
                            seconds: s.wall_seconds - snapshot_seconds,
                            searching_pixels: 0,
                        });
                        let index = serde_json::to_string_pretty(&snapshots).unwrap_or_default();
                        image::write_atomically(&snap.dir.join("snapshots.json"), index.as_bytes())
                            .map_err(GpuError::Gl)?;
                    }
                    explain.push(ExplainLine {
                        stage: "radiance estimate".into(),
                        passes: s.passes as usize,
                        ran: true,
                        why: format!(
                            "kNN-grid, k = {k}, max radius {max_radius}, {} steps per pixel per pass, {:?}; {} of {} pixels have a diffuse hit, {} tile draws{}",
                            gi.estimate.budget,
                            gi.estimate.mode,
                            s.query_pixels,
                            options.width as u64 * options.height as u64,
                            s.tile_draws,
                            if spp > 1 { format!(" (sample {})", sample + 1) } else { String::new() }
                        ),
                    });
                    stats = Some(s);
                    image
                }
                _ => direct.read_radiance(),
            };
            sum = Some(match sum {
                None => image,
                Some(mut acc) => {
                    for (a, p) in acc.pixels.iter_mut().zip(&image.pixels) {
                        for c in 0..3 {
                            a[c] += p[c];
                        }
                    }
                    acc
                }
            });
        }
        let mut image = sum.expect("at least one sample");
        if spp > 1 {
            for p in &mut image.pixels {
                for c in p.iter_mut() {
                    *c /= spp as f32;
                }
            }
        }
        on_frame(view, &image).map_err(GpuError::Gl)?;
        last_image = Some(image);
    }
    let image = last_image.expect("at least one camera");
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    let passes = timings.stages.iter().map(|s| s.passes).sum();
    let state = RenderState {
        textures,
        direct,
        map,
        estimate,
    };
    Ok(RenderOutput {
        image,
        state,
        timings,
        passes,
        photons: photon_report,
        estimate: stats,
        snapshots,
        explain,
    })
}
