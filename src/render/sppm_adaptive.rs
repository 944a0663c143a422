//! Adaptive sampling for SPPM (section 4.5's proposal, on the progressive
//! method). SPPM's cost is its gather: each iteration gathers at every
//! pixel's visible point (83 of 99 s in CORNELL BOX at 16 iterations). The
//! first `pilot` iterations run at every pixel. Their photon half,
//! L = tau / (pi R^2 i), then plans the pyramid of `adaptive.rs` once, with
//! the last pilot iteration's first hits as the discontinuity buffer: a pixel
//! is interpolated where its coarser corners share its material and normal
//! and their pilot light agrees within the threshold, and goes on computing
//! elsewhere (also where it had no diffuse hit in that iteration, since a
//! jittered path may find one later).
//!
//! From then on the plan is fixed. The computed pixels' SPPM state (tau, R,
//! N) is packed densely into the first texels of state-shaped textures, and
//! each iteration runs the gather-and-update there only
//! (`glsl/render/sppm_update.frag` over the packed visible points, on the
//! first rows). Direct light still accumulates at every pixel, from every
//! iteration's eye paths, with the gather off. The image interpolates the
//! photon half of the other pixels level by level from the finished corners
//! (`glsl/render/sppm_adaptive_fill.frag`). A computed pixel that gathered
//! photons in the pilot follows the same sequence of states as in a full SPPM
//! render (one that had not takes its first radius from the grid's cell,
//! which now follows the computed pixels' radii only); an interpolated pixel
//! carries the interpolation's error, which does not shrink with iterations,
//! and the error of a plan made on the pilot's still-wide radii: it is fixed
//! for the rest of the render.

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};

use super::adaptive::{Adaptive, AdaptiveOptions, AdaptiveStats, STRIDES};
use super::DirectLight;

/// The pilot when not given: an eighth of the iterations, at least one.
pub fn default_pilot(iterations: u32) -> u32 {
    (iterations / 8).max(1)
}

/// Per-pixel SPPM state: tau.rgb with w = R^2, and the direct-light sum with
/// w = N; updated in place by `glsl/render/sppm_update.frag`.
pub struct SppmState {
    pub flux: Texture,
    pub sums: Texture,
    pub(crate) target: Target,
}

impl SppmState {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self> {
        let t = || Texture::new(gpu, width, height, TexFormat::Rgba32F);
        let (flux, sums) = (t()?, t()?);
        Ok(Self {
            target: Target::new(gpu, &[&flux, &sums])?,
            flux,
            sums,
        })
    }
}

/// The fixed plan and the packed state after the pilot.
pub struct Planned {
    /// Pixels that go on computing, in packed order (y * width + x).
    pub computed: Vec<u32>,
    /// Per pixel: the level (1..=3, of `STRIDES`) that interpolates it, or -1.
    pub fill_levels: Vec<i32>,
    /// Rows of the packed textures that hold computed pixels.
    pub rows: u32,
    pub state: SppmState,
    pub stats: AdaptiveStats,
    fill_level: Texture,
}

pub struct SppmAdaptive {
    gpu: Gpu,
    pub options: AdaptiveOptions,
    /// Iterations at every pixel before the plan.
    pub pilot: u32,
    /// The pyramid's planning passes, packed order and packed first hits.
    pub pyramid: Adaptive,
    pub planned: Option<Planned>,
    pack_state: Program,
    fill: Program,
    value: Texture,
    value_target: Target,
    width: u32,
    height: u32,
}

impl SppmAdaptive {
    pub fn new(
        gpu: &Gpu,
        width: u32,
        height: u32,
        options: AdaptiveOptions,
        pilot: u32,
    ) -> Result<Self> {
        let value = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        Ok(Self {
            gpu: gpu.clone(),
            options,
            pilot,
            pyramid: Adaptive::new(gpu, width, height)?,
            planned: None,
            pack_state: Program::fullscreen(gpu, "render/sppm_adaptive_pack.frag")?,
            fill: Program::fullscreen(gpu, "render/sppm_adaptive_fill.frag")?,
            value_target: Target::new(gpu, &[&value])?,
            value,
            width,
            height,
        })
    }

    /// Plans the pyramid on the pilot's photon half `pilot_light` (full
    /// resolution) and `hits` (the last pilot iteration's first hits), and
    /// packs the computed pixels' `state`.
    pub fn plan(
        &mut self,
        hits: &DirectLight,
        pilot_light: &Texture,
        state: &SppmState,
    ) -> Result<()> {
        let n = (self.width * self.height) as usize;
        let mut interpolated_at = vec![-1i32; n];
        let mut stats = AdaptiveStats::default();
        self.pyramid.clear();
        for (level, &stride) in STRIDES.iter().enumerate() {
            let plan = self.pyramid.plan_level(hits, level, &self.options)?;
            for &p in &plan.interpolated {
                interpolated_at[p as usize] = level as i32;
            }
            self.pyramid.store_unpacked(pilot_light)?;
            let (c, i) = (plan.computed.len() as u64, plan.interpolated.len() as u64);
            stats.computed += c;
            stats.interpolated += i;
            stats.levels.push((stride, c, i));
        }
        // Every pixel not interpolated computes, hit or not in the pilot's
        // last iteration: row-major order keeps neighbours together. The
        // stats count them all (a full SPPM render gathers at every pixel).
        let computed: Vec<u32> = (0..n as u32)
            .filter(|&p| interpolated_at[p as usize] < 0)
            .collect();
        stats.computed = computed.len() as u64;
        stats.pixels_with_hits = n as u64;
        self.pyramid.pack_order(&computed)?;
        let packed = SppmState::new(&self.gpu, self.width, self.height)?;
        self.pack_state
            .bind()
            .texture("u_order", self.pyramid.order())
            .texture("u_state_flux", &state.flux)
            .texture("u_state_direct", &state.sums)
            .draw_fullscreen(&packed.target, &DrawState::PLAIN)?;
        let fill_level = Texture::new(&self.gpu, self.width, self.height, TexFormat::R32I)?;
        fill_level.upload(&interpolated_at)?;
        self.planned = Some(Planned {
            rows: (computed.len() as u32).div_ceil(self.width).max(1),
            computed,
            fill_levels: interpolated_at,
            state: packed,
            stats,
            fill_level,
        });
        Ok(())
    }

    /// The photon half at every pixel after `iterations`: computed pixels
    /// from their packed state, the others interpolated level by level.
    pub fn fill(&self, iterations: u32) -> Result<&Texture> {
        let planned = self.planned.as_ref().expect("fill after the plan");
        for (level, &stride) in STRIDES.iter().enumerate() {
            if level > 0 {
                // This level reads what the coarser ones wrote.
                self.gpu.texture_barrier();
            }
            self.fill
                .bind()
                .texture("u_slot", self.pyramid.slot())
                .texture("u_fill_level", &planned.fill_level)
                .texture("u_packed_flux", &planned.state.flux)
                .texture("u_packed_sums", &planned.state.sums)
                .texture("u_value", &self.value)
                .int("u_level", level as i32)
                .int("u_stride", stride as i32)
                .float("u_iterations", iterations.max(1) as f32)
                .draw_fullscreen(&self.value_target, &DrawState::PLAIN)?;
        }
        self.gpu.texture_barrier();
        Ok(&self.value)
    }
}
