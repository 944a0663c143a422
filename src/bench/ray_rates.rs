//! Rays per second through the renderer's own passes, for `bench meshes`:
//! eye rays (the intersect pass), shadow rays (the direct pass, one sample
//! per light) and photon rays (emission and bounces), each timed by wall
//! clock between glFinish calls and counted by what the pass actually traced.

use serde::Serialize;

use crate::gpu::{Gpu, Result};
use crate::photon::PhotonTracer;
use crate::render::{DirectLight, PassPlan, RayTracer, RenderOptions};
use crate::scene::pack::SceneTextures;
use crate::scene::{Material, Scene};

#[derive(Clone, Debug, Serialize)]
pub struct RayRates {
    pub eye_rays: u64,
    pub eye_seconds: f64,
    pub shadow_rays: u64,
    pub shadow_seconds: f64,
    pub photon_rays: u64,
    pub photon_seconds: f64,
}

impl RayRates {
    pub fn eye_per_second(&self) -> f64 {
        self.eye_rays as f64 / self.eye_seconds
    }
    pub fn shadow_per_second(&self) -> f64 {
        self.shadow_rays as f64 / self.shadow_seconds
    }
    pub fn photon_per_second(&self) -> f64 {
        self.photon_rays as f64 / self.photon_seconds
    }
}

/// The fastest of `repeats` runs of each pass at `width` x `height` (eye and
/// shadow) and for `photons` emitted photons.
pub fn measure(
    gpu: &Gpu,
    scene: &Scene,
    textures: &SceneTextures,
    width: u32,
    height: u32,
    photons: u32,
    repeats: u32,
) -> Result<RayRates> {
    let mut options = RenderOptions::for_scene(scene);
    (options.width, options.height, options.spp) = (width, height, 1);
    let mut plan = PassPlan::new(scene, &options);
    plan.shadow_rays = 1;
    let tracer = RayTracer::new(gpu, width, height)?;
    let direct = DirectLight::new(gpu, width, height)?;
    // Wall clock between glFinish calls: llvmpipe's timer queries miss the
    // fragment work it defers to the flush (src/timing.rs).
    let timed = |f: &dyn Fn() -> Result<()>| -> Result<f64> {
        let mut best = f64::INFINITY;
        for _ in 0..repeats.max(1) {
            gpu.finish();
            let start = std::time::Instant::now();
            f()?;
            gpu.finish();
            best = best.min(start.elapsed().as_secs_f64());
        }
        Ok(best)
    };
    tracer.eye_rays(&scene.camera, &plan, 0, options.seed)?;
    let eye_seconds = timed(&|| tracer.intersect(textures))?;
    // Shadow rays leave diffuse hits only, one per light.
    let materials: Vec<f32> = tracer.hits.position.read_f32();
    let diffuse_hits = materials
        .chunks(4)
        .filter(|p| {
            p[3] >= 0.0
                && matches!(
                    scene.materials.get(p[3] as usize),
                    Some(Material::Diffuse { .. })
                )
        })
        .count() as u64;
    let shadow_seconds = timed(&|| {
        direct.clear();
        direct.shade(textures, &tracer.hits, &plan, 0..1, 0, options.seed)
    })?;
    let photon_tracer = PhotonTracer::new(gpu)?;
    let mut photon_seconds = f64::INFINITY;
    let mut photon_rays = 0;
    for r in 0..repeats.max(1) {
        gpu.finish();
        let start = std::time::Instant::now();
        let frames = photon_tracer.trace(scene, textures, r + 1, photons)?;
        gpu.finish();
        photon_seconds = photon_seconds.min(start.elapsed().as_secs_f64());
        // A photon alive after frame f - 1 is one ray of frame f; frames after
        // the first with none alive may not have been traced at all.
        let incoming = frames.incoming.read_f32();
        let per_frame = 4 * (frames.width * frames.frame_height) as usize;
        photon_rays = 0;
        for frame in incoming.chunks(per_frame).take(frames.frames as usize - 1) {
            let alive = frame.chunks(4).filter(|t| t[3] != 0.0).count() as u64;
            if alive == 0 {
                break;
            }
            photon_rays += alive;
        }
    }
    Ok(RayRates {
        eye_rays: width as u64 * height as u64,
        eye_seconds,
        shadow_rays: diffuse_hits * scene.lights.len() as u64,
        shadow_seconds,
        photon_rays,
        photon_seconds,
    })
}
