//! The ray tracer's passes for one eye sample (the paper's section 3.1):
//! eye rays, then per specular depth the closest hits, shadow rays and the
//! specular continuation, or a pixel's whole eye path in one fused pass.

use crate::gpu::{Gpu, Result};
use crate::scene::pack::SceneTextures;
use crate::scene::Camera;
use crate::timing::Timings;

use super::direct::DirectLight;
use super::observer::{At, Progress, RenderObserver};
use super::plan::PassPlan;
use super::ray_trace::RayTracer;

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
        query.around(pass)?;
        gpu.finish();
        timings.add_since(name, query.seconds(), stage_wall, 1);
        stage_wall = std::time::Instant::now();
        done += 1;
        observer.progress(&Progress::at("ray tracing", done, total, at));
        Ok(())
    };
    if plan.fused {
        timed("eye paths (fused)", &|| {
            tracer.eye_paths_fused(
                textures,
                &direct.target,
                eye.camera,
                plan,
                eye.sample,
                eye.seed,
            )
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
