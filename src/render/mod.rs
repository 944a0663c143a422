//! Figure 1's "ray trace scene" box (and, later, "radiance estimate"): eye rays,
//! hit textures per specular depth, shadow rays, reflection and refraction.

pub mod direct;
pub mod image;
pub mod radiance_estimate;
pub mod ray_trace;
pub mod timing;

use crate::gpu::{Gpu, GpuError, TimerQuery};
use crate::photon::{
    BitonicBuild, BuildMethod, Grid, PhotonMap, PhotonTracer, RandomSource, StencilRouting,
    VertexFeed,
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

/// Renders a scene: the paper's ray tracer (direct light, specular paths) and,
/// with `options.global`, photon tracing, the photon map and the kNN-grid
/// radiance estimate at each eye path's first diffuse hit.
pub fn render(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    progress: Progress<'_>,
) -> Result<RenderOutput, GpuError> {
    let max = crate::gpu::max_texture_size(gpu);
    if options.width > max || options.height > max {
        return Err(GpuError::Gl(format!(
            "image of {} x {} pixels: each side must be 1..={max} on this driver",
            options.width, options.height
        )));
    }
    let textures = SceneTextures::new(gpu, scene)?;
    let tracer = RayTracer::new(gpu, options.width, options.height)?;
    let direct = DirectLight::new(gpu, options.width, options.height)?;
    let mut explain = Vec::new();

    // With nothing specular, an eye path ends at its first hit.
    let specular = scene.has_specular();
    let depths = if specular {
        scene.render.max_specular_depth + 1
    } else {
        1
    };
    let batches = scene
        .render
        .shadow_rays
        .div_ceil(options.shadow_batch.max(1));
    let has_area = scene
        .lights
        .iter()
        .any(|l| matches!(l, crate::scene::Light::Area { .. }));
    let direct_passes = if has_area { batches } else { 1 };
    let total = 1 + depths as usize * (1 + direct_passes as usize) + (depths as usize - 1);
    let mut done = 0;
    let mut timings = Timings::default();
    let wall = std::time::Instant::now();
    let query = TimerQuery::new(gpu)?;

    // Each pass: GPU time by timer query, wall time with glFinish on both sides.
    direct.clear();
    gpu.finish();
    let mut stage_wall = std::time::Instant::now();
    let mut tick = |timings: &mut Timings, name: &str, q: &TimerQuery| {
        gpu.finish();
        timings.add_both(name, q.seconds(), stage_wall.elapsed().as_secs_f64(), 1);
        stage_wall = std::time::Instant::now();
        done += 1;
        progress("ray tracing", done as u64, total as u64);
    };

    query.begin();
    tracer.eye_rays(&scene.camera, options);
    query.end();
    tick(&mut timings, "eye rays", &query);
    for depth in 0..depths {
        query.begin();
        tracer.intersect(&textures);
        query.end();
        tick(&mut timings, "intersect", &query);
        for b in 0..direct_passes {
            let begin = b * options.shadow_batch;
            let end = ((b + 1) * options.shadow_batch).min(scene.render.shadow_rays);
            query.begin();
            direct.shade(
                &textures,
                &tracer.hits,
                scene.render.shadow_rays,
                begin..end,
                depth,
                options.seed,
            );
            query.end();
            tick(&mut timings, "shadow rays", &query);
        }
        if depth + 1 < depths {
            query.begin();
            tracer.specular(&textures, depth, options.seed);
            query.end();
            tick(&mut timings, "specular", &query);
        }
    }
    gpu.check("ray tracing")?;
    explain.push(ExplainLine {
        stage: "eye rays".into(),
        passes: 1,
        ran: true,
        why: "one ray per pixel centre".into(),
    });
    explain.push(ExplainLine {
        stage: "intersect".into(),
        passes: depths as usize,
        ran: true,
        why: if specular {
            format!(
                "one per specular depth 0..={}",
                scene.render.max_specular_depth
            )
        } else {
            "depth 0 only: the scene has no mirror or glass".into()
        },
    });
    explain.push(ExplainLine {
        stage: "shadow rays".into(),
        passes: depths as usize * direct_passes as usize,
        ran: true,
        why: if has_area {
            format!(
                "{} samples per area light in batches of {} at each depth",
                scene.render.shadow_rays, options.shadow_batch
            )
        } else {
            "one ray per point light at each depth".into()
        },
    });
    explain.push(ExplainLine {
        stage: "specular".into(),
        passes: depths as usize - 1,
        ran: specular,
        why: if specular {
            "reflect or refract at mirror and glass hits".into()
        } else {
            "skipped: no specular surface".into()
        },
    });

    let Some(gi) = &options.global else {
        explain.push(ExplainLine {
            stage: "photons, map, estimate".into(),
            passes: 0,
            ran: false,
            why: "skipped: direct light only".into(),
        });
        let image = direct.read_radiance();
        timings.wall_seconds = wall.elapsed().as_secs_f64();
        let state = RenderState {
            textures,
            direct,
            map: None,
            estimate: None,
        };
        return Ok(RenderOutput {
            image,
            state,
            timings,
            passes: done,
            photons: None,
            estimate: None,
            snapshots: vec![],
            explain,
        });
    };

    // Trace photons and build the map.
    let random = if gi.faithful {
        RandomSource::Texture
    } else {
        RandomSource::Hash
    };
    let photon_tracer = PhotonTracer::with_random(gpu, random)?;
    progress("photons", 0, 1);
    gpu.finish();
    let t0 = std::time::Instant::now();
    let (frames, report) = photon_tracer.trace_to_stored(scene, &textures, options.seed)?;
    gpu.finish();
    // Wall time covers every attempt at the stored count, and its read-backs.
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
            "emission + {} bounces; {} photons traced ({} attempts), the first {} kept: {} stored",
            frames.frames - 1,
            report.emitted,
            report.attempts.len(),
            report.photons_used,
            report.stored
        ),
    });
    let grid = Grid::for_scene(scene);
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
    for s in &build_timings.stages {
        explain.push(ExplainLine {
            stage: format!("build map: {}", s.name),
            passes: s.passes,
            ran: true,
            why: format!("{:?} build", gi.build),
        });
    }
    gpu.finish();
    let build_passes = build_timings.stages.iter().map(|s| s.passes).sum();
    timings.add_both(
        "build map",
        build_timings.gpu_total(),
        t0.elapsed().as_secs_f64(),
        build_passes,
    );
    drop(frames);

    // The radiance estimate, with snapshots of the running image.
    let (k, max_radius) = (scene.photon_map.k, scene.photon_map.max_radius);
    let estimate = RadianceEstimate::new(gpu, options.width, options.height)?;
    let mut snapshots = Vec::new();
    let mut snapshot_seconds = 0.0;
    let mut last_snapshot = (0u32, 0.0f64);
    let mut snapshot_error = None;
    let estimate_options = EstimateOptions {
        float_addressing: gi.faithful,
        ..gi.estimate.clone()
    };
    let stats = estimate.run(&map, &direct, k, max_radius, &estimate_options, &mut |r| {
        progress(
            "radiance estimate",
            r.query_pixels - r.searching,
            r.query_pixels,
        );
        let Some(snap) = &gi.snapshots else { return };
        let seconds = r.elapsed_seconds - snapshot_seconds;
        let due = match snap.every {
            SnapshotEvery::Passes(n) => r.pass == 0 || r.pass >= last_snapshot.0 + n.max(1),
            SnapshotEvery::Seconds(s) => r.pass == 0 || seconds >= last_snapshot.1 + s,
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
        stats.gpu_seconds,
        stats.wall_seconds - snapshot_seconds,
        stats.passes as usize,
    );
    explain.push(ExplainLine {
        stage: "radiance estimate".into(),
        passes: stats.passes as usize,
        ran: true,
        why: format!(
            "kNN-grid, k = {k}, max radius {max_radius}, {} steps per pixel per pass, {:?}; {} of {} pixels have a diffuse hit, {} tile draws",
            gi.estimate.budget,
            gi.estimate.mode,
            stats.query_pixels,
            options.width as u64 * options.height as u64,
            stats.tile_draws
        ),
    });
    let image = estimate.compose(&textures, &direct, k, max_radius, true, true);
    if let Some(snap) = &gi.snapshots {
        let final_file = format!("snapshot_{:04}.png", snapshots.len());
        image
            .png_bytes()
            .and_then(|b| image::write_atomically(&snap.dir.join(&final_file), &b))
            .map_err(GpuError::Gl)?;
        snapshots.push(SnapshotRecord {
            file: final_file,
            pass: stats.passes,
            seconds: stats.wall_seconds - snapshot_seconds,
            searching_pixels: 0,
        });
        let index = serde_json::to_string_pretty(&snapshots).unwrap_or_default();
        image::write_atomically(&snap.dir.join("snapshots.json"), index.as_bytes())
            .map_err(GpuError::Gl)?;
    }
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    let state = RenderState {
        textures,
        direct,
        map: Some(map),
        estimate: Some(estimate),
    };
    Ok(RenderOutput {
        image,
        state,
        timings,
        passes: done,
        photons: Some(report),
        estimate: Some(stats),
        snapshots,
        explain,
    })
}
