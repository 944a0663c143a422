//! Final gather, the paper's first proposal of section 4.5, as Jensen's photon
//! mapping uses it: at each eye path's first diffuse hit, cosine-distributed
//! gather rays sample the incident light, and a *global* photon map (every
//! diffuse hit, direct ones included) estimates the light only where those
//! rays land. Caustics at the first hit come from a separate *caustic* map,
//! visualised directly, and direct light from the shadow rays, so each light
//! path is counted once.
//!
//! Gather rays go in batches of fragment passes, like the shadow rays: a batch
//! of B rays per pixel is one `gather_rays` pass into a width x (height x B)
//! texture of queries, one kNN-grid estimate over it (the same search, tiles and
//! occlusion queries as the first hits'), and one `gather_accumulate` pass that
//! adds the batch to each pixel with additive blending.

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::photon::PhotonMap;
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;

use super::radiance_estimate::{LeakTest, QueryPoints};
use super::{DirectLight, EstimateOptions, Image, RadianceEstimate, Timings};

/// Gather-ray queries in one batch are capped near this many texels (the
/// estimate state is three RGBA textures of that size).
const BATCH_TEXELS: u64 = 1 << 20;

/// How final gather runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FinalGatherOptions {
    /// Gather rays per pixel per eye sample.
    pub rays: u32,
    /// k of the global map's estimate at each gather ray's hit.
    pub k: u32,
    /// The leak test of those estimates (the first hits' caustic estimate
    /// keeps the render's own).
    pub leak: LeakTest,
}

impl Default for FinalGatherOptions {
    /// 16 rays; k = 50 and no leak test, as Jensen's secondary lookups (chosen
    /// a priori, not tuned against any reference).
    fn default() -> Self {
        Self {
            rays: 16,
            k: 50,
            leak: LeakTest::None,
        }
    }
}

/// What one eye sample's gather did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct GatherStats {
    pub rays_per_pixel: u32,
    pub batches: u32,
    /// Gather rays that reached a diffuse surface (queries of the global map).
    pub queries: u64,
    pub estimate_passes: u32,
}

/// The gather rays of one batch at one image size: each pixel's rays from
/// its first diffuse hit, traced to the diffuse hit each ends at
/// (`gather_rays.frag`). Final gather, IGI's bias compensation and
/// radiosity's gather read what lies at those hits.
pub struct GatherRays {
    height: u32,
    /// Gather rays per pixel in one batch.
    pub batch: u32,
    /// The hits, width x (height x batch): w = 1 where a ray ended on a
    /// diffuse surface.
    pub position: Texture,
    /// Facing the gather ray, w = material + 1.
    pub normal: Texture,
    /// The specular chain's throughput, w = the primitive hit.
    pub throughput: Texture,
    target: Target,
    program: Program,
    /// Bound as u_pixel when the first hits are in place (never read).
    no_pixels: Texture,
}

/// The textures and programs of final gather at one image size.
pub struct FinalGather {
    gpu: Gpu,
    width: u32,
    height: u32,
    pub rays: GatherRays,
    pub estimate: RadianceEstimate,
    pub indirect: Texture,
    indirect_target: Target,
    accumulate: Program,
}

/// Rays per batch for an image of width x height: as many of `rays` as fit
/// `BATCH_TEXELS` and the driver's texture height, at least one.
pub fn batch_size(width: u32, height: u32, rays: u32, max_texture: u32) -> u32 {
    let by_texels = (BATCH_TEXELS / (width as u64 * height as u64).max(1)) as u32;
    let by_height = max_texture / height.max(1);
    rays.min(by_texels).min(by_height).max(1)
}

impl GatherRays {
    /// Room for `rays` a pixel of a width x height image, in batches of
    /// `batch_size` rays.
    pub fn new(gpu: &Gpu, width: u32, height: u32, rays: u32) -> Result<Self> {
        let batch = batch_size(width, height, rays, gpu.max_texture_size());
        let t = || Texture::new(gpu, width, height * batch, TexFormat::Rgba32F);
        let (position, normal, throughput) = (t()?, t()?, t()?);
        Ok(Self {
            height,
            batch,
            target: Target::new(gpu, &[&position, &normal, &throughput])?,
            position,
            normal,
            throughput,
            program: Program::fullscreen(gpu, "render/gather_rays.frag")?,
            no_pixels: Texture::new(gpu, 1, 1, TexFormat::R32I)?,
        })
    }

    /// The height of the image whose rays these are (ray j of a batch is
    /// row y + j x height).
    pub fn image_height(&self) -> u32 {
        self.height
    }

    /// The hits of the last batch, as queries.
    pub fn queries(&self) -> QueryPoints<'_> {
        QueryPoints {
            position: &self.position,
            normal: &self.normal,
            pixel: None,
        }
    }

    /// Traces gather rays `rays` (at most `batch` of them) of every pixel from
    /// its first diffuse hit; the batch's unused slots hold no query. Each
    /// ray follows at most `max_depth` mirrors and glass. With `fade` = IGI's
    /// bound m > 0, only what that bound leaves out is gathered
    /// (`gather_rays.frag`).
    pub fn trace_batch(
        &self,
        scene: &SceneTextures,
        first: QueryPoints<'_>,
        rays: std::ops::Range<u32>,
        (max_depth, fade): (u32, f32),
        seed: u32,
    ) -> Result<()> {
        let mut b = self.program.bind();
        scene.bind(&mut b);
        b.texture("u_diffuse_position", first.position)
            .texture("u_diffuse_normal", first.normal)
            .texture("u_pixel", first.pixel.unwrap_or(&self.no_pixels))
            .int("u_packed", first.pixel.is_some() as i32)
            .uint("u_seed", seed)
            .int("u_first_ray", rays.start as i32)
            .int("u_batch_rays", rays.len() as i32)
            .int("u_image_height", self.height as i32)
            .int("u_max_depth", max_depth as i32)
            .float("u_fade_distance", fade)
            .draw_fullscreen(&self.target, &DrawState::PLAIN)
    }
}

impl FinalGather {
    pub fn new(gpu: &Gpu, width: u32, height: u32, rays: u32) -> Result<Self> {
        let rays = GatherRays::new(gpu, width, height, rays)?;
        let indirect = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let indirect_target = Target::new(gpu, &[&indirect])?;
        Ok(Self {
            gpu: gpu.clone(),
            width,
            height,
            estimate: RadianceEstimate::new(gpu, width, height * rays.batch)?,
            rays,
            indirect,
            indirect_target,
            accumulate: Program::fullscreen(gpu, "render/gather_accumulate.frag")?,
        })
    }

    /// Adds the finished batch (`rays` of them) to each pixel's indirect light.
    fn accumulate_batch(
        &self,
        scene: &SceneTextures,
        direct: &DirectLight,
        rays: u32,
        k: u32,
        max_radius: f32,
        total_rays: u32,
    ) -> Result<()> {
        let mut b = self
            .estimate
            .bind_result(&self.accumulate, scene, direct, k, max_radius);
        b.texture("u_gather_normal", &self.rays.normal)
            .texture("u_gather_throughput", &self.rays.throughput)
            .int("u_batch", rays as i32)
            .int("u_image_height", self.height as i32)
            .float("u_total_rays", total_rays as f32)
            .draw_fullscreen(&self.indirect_target, &DrawState::ADDITIVE)
    }

    /// All gather rays of one eye sample from the first hits `first` (all of
    /// them, or the pixels adaptive sampling computes): the indirect light of
    /// each, left in `indirect`; `fade` as `trace_batch` takes it. Adds the
    /// stages "gather rays", "gather estimate" and "gather sum" to `timings`.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        scene: &SceneTextures,
        direct: &DirectLight,
        first: QueryPoints<'_>,
        global: &PhotonMap,
        options: &FinalGatherOptions,
        estimate: &EstimateOptions,
        max_radius: f32,
        depth_and_fade: (u32, f32),
        seed: u32,
        timings: &mut Timings,
        on_batch: &mut dyn FnMut(u32, u32),
    ) -> Result<GatherStats> {
        self.indirect_target.clear([0.0; 4]);
        let mut stats = GatherStats {
            rays_per_pixel: options.rays,
            ..Default::default()
        };
        let timer = crate::gpu::Query::timer(&self.gpu)?;
        let mut done = 0;
        while done < options.rays {
            crate::interrupt::check()?;
            let rays = self.rays.batch.min(options.rays - done);
            self.gpu.finish();
            let t0 = std::time::Instant::now();
            timer.around(|| {
                self.rays
                    .trace_batch(scene, first, done..done + rays, depth_and_fade, seed)
            })?;
            self.gpu.finish();
            timings.add_since("gather rays", timer.seconds(), t0, 1);
            let run = self.estimate.run(
                scene,
                global,
                self.rays.queries(),
                options.k,
                max_radius,
                estimate,
                &mut |_| {},
            )?;
            timings.add_both(
                "gather estimate",
                run.gpu_seconds,
                run.wall_seconds,
                run.passes as usize,
            );
            let t0 = std::time::Instant::now();
            timer.around(|| {
                self.accumulate_batch(scene, direct, rays, options.k, max_radius, options.rays)
            })?;
            self.gpu.finish();
            timings.add_since("gather sum", timer.seconds(), t0, 1);
            stats.batches += 1;
            stats.queries += run.query_pixels;
            stats.estimate_passes += run.passes;
            done += rays;
            on_batch(done, options.rays);
        }
        self.gpu.check("final gather")?;
        Ok(stats)
    }

    pub fn read_indirect(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.indirect.read_f32())
    }
}

/// The two scenes whose photon maps final gather uses: the caustic map (paths
/// of only specular bounces from the light, stored at their first diffuse hit)
/// and the global map (every diffuse hit, the first included). A scene that
/// stores caustics only has no diffuse interreflection to gather.
pub fn map_scenes(scene: &Scene) -> Result<(Scene, Scene)> {
    if scene.photon_map.caustics_only {
        return Err(Error::InvalidOption(format!(
            "final gather samples diffuse interreflection, which {} leaves out \
             (photon_map.caustics_only = true); render it without --final-gather",
            scene.name
        )));
    }
    let mut caustic = scene.clone();
    caustic.photon_map.caustics_only = true;
    caustic.photon_map.store_direct = false;
    Ok((caustic, global_scene(scene)))
}

/// The scene whose photon map is a global map: every diffuse hit stored,
/// the first included (final gather's, and IGI's bias compensation's).
pub fn global_scene(scene: &Scene) -> Scene {
    let mut global = scene.clone();
    global.photon_map.caustics_only = false;
    global.photon_map.specular_last_only = false;
    global.photon_map.store_direct = true;
    global
}

/// The global map's seed for a render seeded `seed`: independent of the
/// caustic map's photons (which take `seed` itself) and of the VPLs.
pub fn global_seed(seed: u32) -> u32 {
    crate::random::pcg_hash(seed ^ crate::layout::GATHER_STREAM)
}
