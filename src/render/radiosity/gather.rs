//! Final gather over the radiosity solution (`--gather-rays N`): the
//! remedy for element resolution near contact. Read at a pixel, the
//! solution is its element's mean, which misses how the light changes
//! across the element where a face meets the floor it stands on or a shadow
//! crosses it. Gathered, each pixel takes the cosine-weighted mean of the
//! radiosity of the surfaces its rays reach, so an element's error enters
//! only as the share of the hemisphere that element covers.
//!
//! A batch of rays a pixel is traced as final gather's are
//! (`gather_rays.frag`, straight to the first surface: light that reaches
//! the pixel through a mirror or glass is the caustic map's, with
//! `--caustic-paths all`; `from-lights` leaves light a diffuse surface sends
//! through them out, as the lookup at the pixel does), the solution is
//! read at each ray's hit by the same lookup as at the first hits
//! (`lookup.frag`: all the hit sends back, its direct light from a shadow
//! ray a light instead of its element's), and `gather_sum.frag` adds the
//! batch to each pixel.

use crate::gpu::{DrawState, Gpu, Result, Target, TexFormat, Texture};
use crate::render::final_gather::GatherRays;
use crate::render::{DirectLight, Timings};
use crate::scene::pack::SceneTextures;

use super::{GatherBatch, LookupAt, Radiosity};

/// The gather's rays and the solution read at their hits.
pub struct SolutionGather {
    pub rays: GatherRays,
    /// The radiance each ray of the last batch brings back, B / pi at its
    /// hit (0 where it reached no patch).
    pub gathered: Texture,
    gathered_target: Target,
    rays_per_pixel: u32,
}

impl SolutionGather {
    /// Room for `rays` a pixel of a width x height image.
    pub fn new(gpu: &Gpu, width: u32, height: u32, rays: u32) -> Result<Self> {
        let rays_textures = GatherRays::new(gpu, width, height, rays)?;
        let gathered = Texture::new(gpu, width, height * rays_textures.batch, TexFormat::Rgba32F)?;
        Ok(Self {
            gathered_target: Target::new(gpu, &[&gathered])?,
            gathered,
            rays: rays_textures,
            rays_per_pixel: rays,
        })
    }

    /// Gather rays a pixel.
    pub fn rays_per_pixel(&self) -> u32 {
        self.rays_per_pixel
    }

    /// Every batch of one eye sample, summed into `radiosity`'s `indirect`.
    /// Adds "gather rays", "gather lookup" and "gather sum" to `timings`.
    pub(super) fn run(
        &self,
        radiosity: &Radiosity,
        textures: &SceneTextures,
        direct: &DirectLight,
        seed: u32,
        timings: &mut Timings,
        on_batch: &mut dyn FnMut(u32, u32),
    ) -> Result<()> {
        let gpu = &radiosity.gpu;
        radiosity.indirect_target.clear([0.0; 4]);
        let mut done = 0;
        while done < self.rays_per_pixel {
            crate::interrupt::check()?;
            let rays = self.rays.batch.min(self.rays_per_pixel - done);
            gpu.finish();
            let t0 = std::time::Instant::now();
            // No mirror or glass on the way: that light is the caustic map's
            // (with --caustic-paths all).
            self.rays.trace_batch(
                textures,
                direct.queries(),
                done..done + rays,
                (0, 0.0),
                seed,
            )?;
            gpu.finish();
            timings.add_since("gather rays", 0.0, t0, 1);
            let t0 = std::time::Instant::now();
            radiosity.lookup(
                textures,
                LookupAt {
                    position: &self.rays.position,
                    normal: &self.rays.normal,
                    throughput: &self.rays.throughput,
                },
                Some(GatherBatch {
                    seed,
                    first_ray: done,
                    image_height: self.rays.image_height(),
                }),
                &self.gathered_target,
            )?;
            gpu.finish();
            timings.add_since("gather lookup", 0.0, t0, 1);
            let t0 = std::time::Instant::now();
            let mut b = radiosity.programs.gather_sum.bind();
            textures.bind(&mut b);
            direct.bind_weights(&mut b);
            b.texture("u_gathered", &self.gathered)
                .int("u_batch", rays as i32)
                .int("u_image_height", self.rays.image_height() as i32)
                .float("u_total_rays", self.rays_per_pixel as f32)
                .draw_fullscreen(&radiosity.indirect_target, &DrawState::ADDITIVE)?;
            drop(b);
            gpu.finish();
            timings.add_since("gather sum", 0.0, t0, 1);
            done += rays;
            on_batch(done, self.rays_per_pixel);
        }
        gpu.check("radiosity gather")
    }
}
