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
    /// into `packed`. Returns (computed, interpolated).
    pub fn select(
        &self,
        direct: &DirectLight,
        level: usize,
        options: &AdaptiveOptions,
    ) -> Result<(u64, u64)> {
        self.select
            .bind()
            .texture("u_first_position", &direct.diffuse_position)
            .texture("u_first_normal", &direct.diffuse_normal)
            .texture("u_value", &self.value)
            .int("u_stride", STRIDES[level] as i32)
            .int("u_coarsest", (level == 0) as i32)
            .float("u_threshold", options.threshold)
            .draw_fullscreen(&self.plan_target, &DrawState::PLAIN)?;
        let plan = self.plan.read_f32();
        let n = (self.width * self.height) as usize;
        let (mut order, mut slot) = (vec![-1i32; n], vec![-1i32; n]);
        let (mut computed, mut interpolated) = (0usize, 0u64);
        for (pixel, texel) in plan.chunks(4).enumerate() {
            if texel[3] == PLAN_COMPUTE as f32 {
                order[computed] = pixel as i32;
                slot[pixel] = computed as i32;
                computed += 1;
            } else if texel[3] == PLAN_INTERPOLATE as f32 {
                interpolated += 1;
            }
        }
        self.order.upload(&order)?;
        self.slot.upload(&slot)?;
        self.pack
            .bind()
            .texture("u_order", &self.order)
            .texture("u_first_position", &direct.diffuse_position)
            .texture("u_first_normal", &direct.diffuse_normal)
            .texture("u_first_throughput", &direct.diffuse_throughput)
            .draw_fullscreen(&self.packed.target, &DrawState::PLAIN)?;
        Ok((computed as u64, interpolated))
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
        // An absent source is never read; the plan stands in for its sampler.
        let mut b = self.store.bind();
        b.texture("u_plan", &self.plan)
            .texture("u_slot", &self.slot)
            .texture("u_estimate", estimate.unwrap_or(&self.plan))
            .texture("u_gathered", gathered.unwrap_or(&self.plan))
            .int("u_has_estimate", estimate.is_some() as i32)
            .int("u_has_gather", gathered.is_some() as i32)
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
