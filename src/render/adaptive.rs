//! Adaptive sampling, the paper's last proposal of section 4.5: "initially
//! computes a low resolution image and then builds successively higher
//! resolution images by interpolating in low variance areas and tracing
//! additional rays in high variance areas".
//!
//! What adapts is the expensive half of a pixel, its global light (the
//! radiance estimate, and final gather's rays); direct light and specular
//! paths stay at full resolution, and their first hits (material, normal)
//! are the discontinuity buffer. Levels have strides 8, 4, 2, 1. The first
//! computes every 8th pixel of every 8th row. Each next level's new lattice
//! pixels are interpolated bilinearly from the coarser lattice around them
//! where all those corners see the same material with a similar normal and
//! their light differs by at most `threshold` of its mean, and computed
//! otherwise (glsl/render/adaptive_plan.glsl). A computed pixel is the same
//! number a full render gives it.
//!
//! The pixels to compute are packed densely before the estimate runs: on a
//! sparse lattice every SIMD block of fragments would hold one live pixel and
//! cost as much as a full one (measured: no time saved without packing). The
//! plan is read back and the packed order built on the CPU and uploaded (two
//! integers a pixel per level); a GPU prefix sum would remove that round
//! trip. The packed queries fill the first rows of full-size textures, and
//! the estimate's computation mask (the tiles' occlusion queries, or the
//! stencil in masked mode) drops the empty rest after its first pass.

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::layout::{PLAN_COMPUTE, PLAN_INTERPOLATE};

use super::radiance_estimate::QueryPoints;
use super::{DirectLight, Image};

/// The levels' strides, coarsest first.
pub const STRIDES: [u32; 4] = [8, 4, 2, 1];

/// How adaptive sampling decides.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct AdaptiveOptions {
    /// A pixel is interpolated where its corners' global light spans at most
    /// this fraction of their interpolated mean.
    pub threshold: f32,
}

impl Default for AdaptiveOptions {
    /// 0.1: the corners agree to 10%, a priori (not tuned against a reference).
    fn default() -> Self {
        Self { threshold: 0.1 }
    }
}

/// What one eye sample's adaptive pass did, level by level.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct AdaptiveStats {
    /// Pixels with a first diffuse hit (a full render computes them all).
    pub pixels_with_hits: u64,
    pub computed: u64,
    pub interpolated: u64,
    /// (stride, computed, interpolated) per level.
    pub levels: Vec<(u32, u64, u64)>,
}

/// One level's plan: the pixels (y * width + x) it computes and interpolates.
#[derive(Clone, Debug, Default)]
pub struct LevelPlan {
    pub computed: Vec<u32>,
    pub interpolated: Vec<u32>,
}

pub struct Adaptive {
    gpu: Gpu,
    /// The first hits computed at the current level, packed (texel i: the
    /// i-th such pixel, row by row), shaped like the direct-light pass's.
    pub packed: DirectLight,
    /// Packed texel -> pixel index, and pixel -> packed texel (-1: none).
    order: Texture,
    slot: Texture,
    /// rgb interpolated, w = plan.
    pub plan: Texture,
    plan_target: Target,
    /// Global light known so far, w = 1 where known.
    pub value: Texture,
    value_target: Target,
    select: Program,
    pack: Program,
    store: Program,
    width: u32,
    height: u32,
}

impl Adaptive {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self> {
        let t = || Texture::new(gpu, width, height, TexFormat::Rgba32F);
        let (plan, value) = (t()?, t()?);
        let index = || Texture::new(gpu, width, height, TexFormat::R32I);
        Ok(Self {
            gpu: gpu.clone(),
            packed: DirectLight::new(gpu, width, height)?,
            order: index()?,
            slot: index()?,
            plan_target: Target::new(gpu, &[&plan])?,
            value_target: Target::new(gpu, &[&value])?,
            plan,
            value,
            select: Program::fullscreen(gpu, "render/adaptive_select.frag")?,
            pack: Program::fullscreen(gpu, "render/adaptive_compact.frag")?,
            store: Program::fullscreen(gpu, "render/adaptive_store.frag")?,
            width,
            height,
        })
    }

    /// Forgets the last eye sample's light.
    pub fn clear(&self) {
        self.value_target.clear([0.0; 4]);
    }

    /// Plans level `level` (of `STRIDES`) and packs the first hits to compute
    /// into `packed`. Returns the level's pixels, computed and interpolated.
    pub fn select(
        &self,
        direct: &DirectLight,
        level: usize,
        options: &AdaptiveOptions,
    ) -> Result<LevelPlan> {
        let plan = self.plan_level(direct, level, options)?;
        self.pack_order(&plan.computed)?;
        self.pack_hits(direct)?;
        Ok(plan)
    }

    /// Plans level `level` only (adaptive SPPM packs once, after all levels).
    pub fn plan_level(
        &self,
        direct: &DirectLight,
        level: usize,
        options: &AdaptiveOptions,
    ) -> Result<LevelPlan> {
        self.select
            .bind()
            .texture("u_first_position", &direct.diffuse_position)
            .texture("u_first_normal", &direct.diffuse_normal)
            .texture("u_value", &self.value)
            .int("u_stride", STRIDES[level] as i32)
            .int("u_coarsest", (level == 0) as i32)
            .float("u_threshold", options.threshold)
            .draw_fullscreen(&self.plan_target, &DrawState::PLAIN)?;
        let mut plan = LevelPlan::default();
        for (pixel, texel) in self.plan.read_f32().chunks(4).enumerate() {
            if texel[3] == PLAN_COMPUTE as f32 {
                plan.computed.push(pixel as u32);
            } else if texel[3] == PLAN_INTERPOLATE as f32 {
                plan.interpolated.push(pixel as u32);
            }
        }
        Ok(plan)
    }

    /// Sets the packed order: texel i of the packed textures is `pixels[i]`
    /// (pixel indices, y * width + x), and every other pixel has no slot.
    pub fn pack_order(&self, pixels: &[u32]) -> Result<()> {
        let n = (self.width * self.height) as usize;
        let (mut order, mut slot) = (vec![-1i32; n], vec![-1i32; n]);
        for (i, &pixel) in pixels.iter().enumerate() {
            order[i] = pixel as i32;
            slot[pixel as usize] = i as i32;
        }
        self.order.upload(&order)?;
        self.slot.upload(&slot)
    }

    /// Packs `direct`'s first hits of the pixels in the packed order into `packed`.
    pub fn pack_hits(&self, direct: &DirectLight) -> Result<()> {
        self.pack
            .bind()
            .texture("u_order", &self.order)
            .texture("u_first_position", &direct.diffuse_position)
            .texture("u_first_normal", &direct.diffuse_normal)
            .texture("u_first_throughput", &direct.diffuse_throughput)
            .draw_fullscreen(&self.packed.target, &DrawState::PLAIN)
    }

    /// Packed texel -> pixel index (-1: none), and pixel -> packed texel.
    pub fn order(&self) -> &Texture {
        &self.order
    }

    pub fn slot(&self) -> &Texture {
        &self.slot
    }

    /// This level's packed first hits, as queries.
    pub fn queries(&self) -> QueryPoints<'_> {
        QueryPoints {
            pixel: Some(&self.order),
            ..self.packed.queries()
        }
    }

    /// Stores this level's light: computed (the packed `estimate` without
    /// direct light plus the packed `gathered`) or interpolated.
    pub fn store(&self, estimate: Option<&Texture>, gathered: Option<&Texture>) -> Result<()> {
        self.store_from(estimate, gathered, true)
    }

    /// Stores this level's light with the computed pixels' light read from
    /// `light`, a full-resolution image (adaptive SPPM plans on its pilot).
    pub fn store_unpacked(&self, light: &Texture) -> Result<()> {
        self.store_from(Some(light), None, false)
    }

    fn store_from(
        &self,
        estimate: Option<&Texture>,
        gathered: Option<&Texture>,
        packed: bool,
    ) -> Result<()> {
        // An absent source is never read; the plan stands in for its sampler.
        let mut b = self.store.bind();
        b.texture("u_plan", &self.plan)
            .texture("u_slot", &self.slot)
            .texture("u_estimate", estimate.unwrap_or(&self.plan))
            .texture("u_gathered", gathered.unwrap_or(&self.plan))
            .int("u_has_estimate", estimate.is_some() as i32)
            .int("u_has_gather", gathered.is_some() as i32)
            .int("u_packed", packed as i32)
            .draw_fullscreen(&self.value_target, &DrawState::PLAIN)?;
        // Finished here, so that the caller's clock measures the pass.
        self.gpu.finish();
        Ok(())
    }

    /// The global light of every pixel (after the last level).
    pub fn read_value(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.value.read_f32())
    }
}
