//! The ray tracer's passes for a scene, derived once from it and the options:
//! what every eye sample runs, what the scene lets it skip, and the counts
//! `--explain` and the progress bar report.

use crate::scene::{Light, Scene};

#[derive(Clone, Debug, PartialEq)]
pub struct PassPlan {
    pub width: u32,
    pub height: u32,
    /// Eye samples per pixel (at least 1).
    pub spp: u32,
    /// Eye rays through a jittered point of their stratum (more than one
    /// sample per pixel, or a progressive method), else the pixel centre.
    pub jitter: bool,
    /// The scene has a mirror or glass: eye paths continue past their first hit.
    pub specular: bool,
    /// The scene has an area light: shadow rays are stratified samples in batches.
    pub has_area: bool,
    pub max_specular_depth: u32,
    /// Intersect passes per eye sample: one per specular depth.
    pub depths: u32,
    /// Shadow samples per area light, and how many go in one pass.
    pub shadow_rays: u32,
    pub shadow_batch: u32,
    /// Shadow-ray passes per depth: batches of area-light samples, or one.
    pub direct_passes: u32,
    /// Shadow rays sample the lights (off when photons carry direct light).
    pub light_sampling: bool,
    /// Each eye path in one fused pass (`render/eye_path.frag`) instead of
    /// the paper's pass per bounce: the same image to rounding.
    pub fused: bool,
}

/// What of a render's options the plan depends on.
#[derive(Clone, Copy, Debug)]
pub struct FrameSize {
    pub width: u32,
    pub height: u32,
    pub spp: u32,
    /// Shadow samples per area light a pass (0: chosen by image size).
    pub shadow_batch: u32,
    /// Each eye path in one fused pass.
    pub fused: bool,
}

/// Shadow rays one pass draws at most, when the batch is chosen by image size.
pub const SHADOW_RAYS_PER_PASS: u64 = 1 << 23;

impl PassPlan {
    pub fn new(scene: &Scene, frame: impl Into<FrameSize>) -> Self {
        let options = frame.into();
        let specular = scene.has_specular();
        let has_area = scene
            .lights
            .iter()
            .any(|l| matches!(l, Light::Area { .. } | Light::Triangles { .. }));
        let shadow_batch = match options.shadow_batch {
            // A pass of about SHADOW_RAYS_PER_PASS rays, at least 8 a pixel:
            // each pass costs more than its rays (a full-screen draw that
            // every later depth repeats), so the paper's 32 shadow rays at
            // 512 x 512 go in one pass, not four.
            0 => {
                let pixels = (options.width as u64 * options.height as u64).max(1);
                (SHADOW_RAYS_PER_PASS / pixels).clamp(8, u32::MAX as u64) as u32
            }
            n => n,
        };
        Self {
            width: options.width,
            height: options.height,
            spp: options.spp.max(1),
            jitter: options.spp > 1,
            specular,
            has_area,
            max_specular_depth: scene.render.max_specular_depth,
            // With nothing specular, an eye path ends at its first hit.
            depths: if specular {
                scene.render.max_specular_depth + 1
            } else {
                1
            },
            shadow_rays: scene.render.shadow_rays,
            shadow_batch,
            direct_passes: if has_area {
                scene.render.shadow_rays.div_ceil(shadow_batch)
            } else {
                1
            },
            light_sampling: true,
            fused: options.fused,
        }
    }

    /// The shadow samples of batch `b`.
    pub fn shadow_batch(&self, b: u32) -> std::ops::Range<u32> {
        let begin = b * self.shadow_batch;
        begin..((b + 1) * self.shadow_batch).min(self.shadow_rays)
    }

    /// Ray-tracing passes of one eye sample: eye rays, then per depth an
    /// intersect and the shadow batches, and a specular pass between depths;
    /// fused, one.
    pub fn passes_per_sample(&self) -> u32 {
        if self.fused {
            return 1;
        }
        1 + self.depths * (1 + self.direct_passes) + (self.depths - 1)
    }
}
