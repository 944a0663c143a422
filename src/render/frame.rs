//! The frame, as the paper's Figure 1 draws it: prepare the method (trace
//! photons and build the photon map, or the method's own), then for each
//! view and eye sample ray trace the scene and take the method's light at
//! each first diffuse hit, and average the samples into the image.

use crate::error::Error;
use crate::gpu::{Gpu, PixelWindow, Result};
use crate::image::Image;
use crate::scene::pack::SceneTextures;
use crate::scene::{Camera, Scene};
use crate::timing::Timings;

use super::direct::DirectLight;
use super::eye_paths::{trace_eye_paths, EyeSample};
use super::method::MethodRun;
use super::observer::{At, EstimatePass, Progress, RenderObserver};
use super::options::RenderOptions;
use super::output::{FrameState, RenderOutput};
use super::plan::PassPlan;
use super::ray_trace::RayTracer;
use super::sample::SampleFrame;

/// Renders a scene: the paper's ray tracer (direct light, specular paths) and
/// the method's light at each eye path's first diffuse hit (the paper's:
/// photon tracing, the photon map and the kNN-grid radiance estimate). With
/// `spp` > 1 the method is prepared once and each eye sample (stratified,
/// jittered) runs the ray tracer and the method; the image is their mean (a
/// box filter).
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

/// Renders the scene from each camera in turn with one prepared method (the
/// paper's figure 1: photons are traced and the map built only when geometry
/// or lights change). The observer sees each view's image; the output holds
/// the last.
pub fn render_views(
    gpu: &Gpu,
    scene: &Scene,
    options: &RenderOptions,
    cameras: &[Camera],
    observer: &mut dyn RenderObserver,
) -> Result<RenderOutput> {
    check_request(gpu, options, cameras)?;
    options.check_materials(scene)?;
    let observer = &mut Cropped {
        inner: observer,
        options,
    };
    let plan = PassPlan::new(scene, options);
    let (w, h) = (options.width, options.height);
    let textures = SceneTextures::new(gpu, scene)?;
    let tracer = RayTracer::new(gpu, w, h)?;
    let direct = DirectLight::new(gpu, w, h)?;
    let mut timings = Timings::default();
    let wall = std::time::Instant::now();
    // The method first: one map (or final gather's two) serves every view
    // and every eye sample.
    let mut method = MethodRun::prepare(gpu, scene, &textures, options, &mut timings, observer)?;
    // A crop: the eye passes draw only its pixels and the margin its
    // pixels read (`MethodRun::crop_margin`), or the whole frame where the
    // reads are not local; the image is cut from the frame's either way.
    let crop = options.pixel_bounds;
    let _window = PixelWindowGuard::set(
        gpu,
        crop.zip(method.crop_margin())
            .map(|(b, margin)| PixelWindow {
                size: (w, h),
                rect: b.grown(margin, w, h).gl_rect(h),
            }),
    );
    let cut = |image: Image| options.cut(image);
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
                seed: eye.seed,
                at,
            };
            sum.add(&method.sample(&frame, &mut timings, observer)?);
            observer.samples_done(view, sum.count, &|| cut(sum.mean_so_far()));
        }
        let view_image = cut(sum.mean_so_far());
        observer.frame(view, &view_image)?;
        image = Some(view_image);
    }
    timings.wall_seconds = wall.elapsed().as_secs_f64();
    let passes = timings.passes_total();
    Ok(RenderOutput {
        image: image.expect("at least one camera"),
        timings,
        passes,
        plan,
        state: FrameState { textures, direct },
        method,
    })
}

/// The observer as a crop's render shows it: estimate passes' images cut to
/// the crop, like every other image it sees.
struct Cropped<'a> {
    inner: &'a mut dyn RenderObserver,
    options: &'a RenderOptions,
}

impl RenderObserver for Cropped<'_> {
    fn progress(&mut self, progress: &Progress<'_>) {
        self.inner.progress(progress);
    }

    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> Result<()> {
        if self.options.pixel_bounds.is_none() {
            return self.inner.estimate_pass(pass);
        }
        self.inner.estimate_pass(&EstimatePass {
            image: &|| Ok(self.options.cut(pass.image()?)),
            ..*pass
        })
    }

    fn samples_done(&mut self, view: usize, done: u32, mean: &dyn Fn() -> Image) {
        self.inner.samples_done(view, done, mean);
    }

    fn frame(&mut self, view: usize, image: &Image) -> Result<()> {
        self.inner.frame(view, image)
    }
}

/// The pixel window while it lives: a failed render leaves none behind.
struct PixelWindowGuard<'a>(&'a Gpu);

impl<'a> PixelWindowGuard<'a> {
    fn set(gpu: &'a Gpu, window: Option<PixelWindow>) -> Self {
        gpu.set_pixel_window(window);
        Self(gpu)
    }
}

impl Drop for PixelWindowGuard<'_> {
    fn drop(&mut self) {
        self.0.set_pixel_window(None);
    }
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
    options.check_pixel_bounds()
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

    /// The mean of the samples so far.
    fn mean_so_far(&self) -> Image {
        let mut image = self.sum.clone().expect("at least one sample");
        if self.count > 1 {
            image.divide(self.count as f32);
        }
        image
    }
}
