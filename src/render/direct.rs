//! Direct illumination by shadow rays, emitters seen along eye paths, and the
//! record of each eye path's first diffuse hit (what the radiance estimate reads).

use crate::gpu::{Bindings, DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::scene::pack::SceneTextures;

use super::plan::PassPlan;
use super::ray_trace::HitBuffers;
use super::Image;

pub struct DirectLight {
    /// Accumulated radiance per pixel (linear RGB).
    pub radiance: Texture,
    /// First diffuse hit: position (w = 1 where one exists).
    pub diffuse_position: Texture,
    /// Normal facing the viewer, w = material index + 1.
    pub diffuse_normal: Texture,
    /// Path throughput up to that hit, w = the primitive hit.
    pub diffuse_throughput: Texture,
    pub(crate) target: Target,
    /// The radiance alone: a depth's later batches add only light.
    radiance_target: Target,
    program: Program,
}

pub use crate::sampling::strata;

impl DirectLight {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self> {
        let t = || Texture::new(gpu, width, height, TexFormat::Rgba32F);
        let (radiance, diffuse_position, diffuse_normal, diffuse_throughput) =
            (t()?, t()?, t()?, t()?);
        let target = Target::new(
            gpu,
            &[
                &radiance,
                &diffuse_position,
                &diffuse_normal,
                &diffuse_throughput,
            ],
        )?;
        let radiance_target = Target::new(gpu, &[&radiance])?;
        Ok(Self {
            radiance_target,
            radiance,
            diffuse_position,
            diffuse_normal,
            diffuse_throughput,
            target,
            program: Program::fullscreen(gpu, "render/direct.frag")?,
        })
    }

    pub fn clear(&self) {
        self.target.clear([0.0; 4]);
    }

    /// Adds shadow samples `samples` (of the plan's `shadow_rays` per area
    /// light) for the hits of `depth` (with the plan's `light_sampling` off,
    /// only emitters seen).
    pub fn shade(
        &self,
        scene: &SceneTextures,
        hits: &HitBuffers,
        plan: &PassPlan,
        samples: std::ops::Range<u32>,
        depth: u32,
        seed: u32,
    ) -> Result<()> {
        let (shadow_rays, light_sampling) = (plan.shadow_rays, plan.light_sampling);
        let (nx, _) = strata(shadow_rays);
        let mut b = self.program.bind();
        scene.bind(&mut b);
        hits.bind(&mut b);
        b.uint("u_seed", seed)
            .int("u_depth", depth as i32)
            .int("u_shadow_rays", shadow_rays as i32)
            .int("u_strata_x", nx as i32)
            .int("u_sample_begin", samples.start as i32)
            .int("u_sample_end", samples.end as i32)
            .int("u_light_sampling", light_sampling as i32);
        let target = if samples.start == 0 {
            &self.target
        } else {
            &self.radiance_target
        };
        b.draw_fullscreen(target, &DrawState::ADDITIVE)
    }

    /// What turns light at the first diffuse hits into the pixel's: their
    /// normal (w = material + 1) and the path's throughput up to them, as
    /// `u_diffuse_normal` and `u_diffuse_throughput`.
    pub fn bind_weights(&self, b: &mut Bindings<'_>) {
        b.texture("u_diffuse_normal", &self.diffuse_normal)
            .texture("u_diffuse_throughput", &self.diffuse_throughput);
    }

    /// The first diffuse hits, as the radiance estimate's queries.
    pub fn queries(&self) -> QueryPoints<'_> {
        QueryPoints {
            position: &self.diffuse_position,
            normal: &self.diffuse_normal,
            pixel: None,
        }
    }

    pub fn read_radiance(&self) -> Image {
        Image::from_gl_rgba(
            self.radiance.width,
            self.radiance.height,
            &self.radiance.read_f32(),
        )
    }
}

/// The points a search serves: positions (w = 1 where a query exists) and
/// normals facing the incoming ray (w = material + 1), the same size as the
/// estimate. An eye sample's first diffuse hits (`DirectLight::queries`), or
/// final gather's hits.
#[derive(Clone, Copy)]
pub struct QueryPoints<'a> {
    pub position: &'a Texture,
    pub normal: &'a Texture,
    /// Packed queries (adaptive sampling): each texel's pixel index (R32I),
    /// so that what a query draws at random is its pixel's. None: in place.
    pub pixel: Option<&'a Texture>,
}
