//! Figure 1's "ray trace scene" box (and, later, "radiance estimate"): eye rays,
//! hit textures per specular depth, shadow rays, reflection and refraction.

pub mod direct;
pub mod image;
pub mod ray_trace;
pub mod timing;

use crate::gpu::{Gpu, GpuError, TimerQuery};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;

pub use self::image::Image;
pub use direct::DirectLight;
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
}

impl RenderOptions {
    pub fn for_scene(scene: &Scene) -> Self {
        Self {
            seed: 1,
            width: scene.camera.width,
            height: scene.camera.height,
            shadow_batch: 8,
        }
    }
}

/// What a render leaves behind: the image, and the hit records the radiance
/// estimate reads (first diffuse hit of each eye path).
pub struct RenderOutput {
    pub image: Image,
    pub timings: Timings,
    pub passes: usize,
}

/// Something that wants to hear about progress: called with (passes done, passes total).
pub type Progress<'a> = &'a dyn Fn(usize, usize);

/// Renders direct light plus specular paths (the paper's ray tracer).
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

    // With nothing specular, an eye path ends at its first hit.
    let depths = if scene.has_specular() {
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

    let mut tick = |timings: &mut Timings, name: &str, q: &TimerQuery| {
        timings.add(name, q.seconds(), 1);
        done += 1;
        progress(done, total);
    };

    direct.clear();
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
    let image = direct.read_radiance();
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    Ok(RenderOutput {
        image,
        timings,
        passes: done,
    })
}
