//! Adaptive sampling on the CPU, the twin of glsl/render/adaptive_plan.glsl,
//! adaptive_select.frag and adaptive_store.frag (and of adaptive SPPM's fill,
//! sppm_adaptive_fill.frag): the same levels, plans and interpolation, with
//! each computed pixel's light taken from a full render.
//! Pixels are in GL order (row 0 at the bottom), as the lattices are.

use glam::Vec3;

use crate::layout::{ADAPTIVE_NORMAL_COS, LUMINANCE};
use crate::render::adaptive::STRIDES;

/// Each pixel's first diffuse hit: its viewer-facing normal and material + 1
/// (0: no diffuse hit), as the direct-light pass records them.
pub struct FirstHits {
    pub width: u32,
    pub height: u32,
    pub normal: Vec<Vec3>,
    pub material: Vec<f32>,
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::from(LUMINANCE))
}

/// The pyramid's result: every pixel's global light, and per level (stride,
/// computed, interpolated).
pub fn adaptive_light(
    first: &FirstHits,
    computed: &dyn Fn(usize) -> Vec3,
    threshold: f32,
) -> (Vec<Vec3>, Vec<(u32, u64, u64)>) {
    let p = adaptive_pyramid(first, computed, threshold);
    (p.value, p.levels)
}

/// The pyramid in full.
pub struct Pyramid {
    /// Every pixel's global light.
    pub value: Vec<Vec3>,
    /// (stride, computed, interpolated) per level.
    pub levels: Vec<(u32, u64, u64)>,
    /// Per pixel: the level (index into `STRIDES`) that interpolates it, or -1.
    pub interpolated_at: Vec<i32>,
}

pub fn adaptive_pyramid(
    first: &FirstHits,
    computed: &dyn Fn(usize) -> Vec3,
    threshold: f32,
) -> Pyramid {
    let (w, h) = (first.width as i32, first.height as i32);
    let mut value = vec![Vec3::ZERO; (w * h) as usize];
    let mut interpolated_at = vec![-1; (w * h) as usize];
    let mut levels = Vec::new();
    for (level, &stride) in STRIDES.iter().enumerate() {
        let s = stride as i32;
        let mut next = value.clone();
        let (mut n_computed, mut n_interpolated) = (0, 0);
        for y in (0..h).step_by(stride as usize) {
            for x in (0..w).step_by(stride as usize) {
                let i = (y * w + x) as usize;
                if level > 0 && x % (2 * s) == 0 && y % (2 * s) == 0 {
                    continue; // known from a coarser level
                }
                if first.material[i] == 0.0 {
                    next[i] = Vec3::ZERO;
                    continue;
                }
                match (level > 0)
                    .then(|| interpolate(first, &value, x, y, s, threshold))
                    .flatten()
                {
                    Some(v) => {
                        next[i] = v;
                        interpolated_at[i] = level as i32;
                        n_interpolated += 1;
                    }
                    None => {
                        next[i] = computed(i);
                        n_computed += 1;
                    }
                }
            }
        }
        value = next;
        levels.push((stride, n_computed, n_interpolated));
    }
    Pyramid {
        value,
        levels,
        interpolated_at,
    }
}

/// Adaptive SPPM's image half on a fixed plan: `computed(i)` at every pixel
/// that no level interpolates, then each level's interpolated pixels from
/// the corners as they stand (the twin of glsl/render/sppm_adaptive_fill.frag).
pub fn fill_planned(
    width: u32,
    height: u32,
    interpolated_at: &[i32],
    computed: &dyn Fn(usize) -> Vec3,
) -> Vec<Vec3> {
    let (w, h) = (width as i32, height as i32);
    let mut value: Vec<Vec3> = (0..(w * h) as usize)
        .map(|i| {
            if interpolated_at[i] < 0 {
                computed(i)
            } else {
                Vec3::ZERO
            }
        })
        .collect();
    for (level, &stride) in STRIDES.iter().enumerate().skip(1) {
        for y in 0..h {
            for x in 0..w {
                let i = (y * w + x) as usize;
                if interpolated_at[i] == level as i32 {
                    value[i] = corners(w, h, x, y, stride as i32)
                        .iter()
                        .filter(|(_, weight)| *weight != 0.0)
                        .map(|&(c, weight)| weight * value[c])
                        .sum();
                }
            }
        }
    }
    value
}

/// The coarser lattice's (stride 2s) corners around (x, y), as pixel
/// indices, with their bilinear weights; past the image's last lattice row or
/// column the near corners carry it all.
fn corners(w: i32, h: i32, x: i32, y: i32, s: i32) -> [(usize, f32); 4] {
    let s2 = 2 * s;
    let (x0, y0) = ((x / s2) * s2, (y / s2) * s2);
    let (x1, y1) = (x0 + s2, y0 + s2);
    let fx = if x1 < w {
        (x - x0) as f32 / s2 as f32
    } else {
        0.0
    };
    let fy = if y1 < h {
        (y - y0) as f32 / s2 as f32
    } else {
        0.0
    };
    std::array::from_fn(|corner| {
        let wx = if corner & 1 != 0 { fx } else { 1.0 - fx };
        let wy = if corner & 2 != 0 { fy } else { 1.0 - fy };
        let cx = if corner & 1 != 0 { x1 } else { x0 };
        let cy = if corner & 2 != 0 { y1 } else { y0 };
        // A zero-weight corner may lie outside the image; it is never read.
        (((cy * w + cx).max(0)) as usize, wx * wy)
    })
}

/// The bilinear light at (x, y) from the coarser lattice (stride 2s) around
/// it, or None where the corners' geometry or light says compute.
fn interpolate(
    first: &FirstHits,
    value: &[Vec3],
    x: i32,
    y: i32,
    s: i32,
    threshold: f32,
) -> Option<Vec3> {
    let (w, h) = (first.width as i32, first.height as i32);
    let i = (y * w + x) as usize;
    let (mut lo, mut hi, mut sum) = (f32::INFINITY, f32::NEG_INFINITY, Vec3::ZERO);
    for (c, weight) in corners(w, h, x, y, s) {
        if weight == 0.0 {
            continue;
        }
        if first.material[c] != first.material[i]
            || first.normal[c].dot(first.normal[i]) < ADAPTIVE_NORMAL_COS
        {
            return None;
        }
        let l = luminance(value[c]);
        (lo, hi) = (lo.min(l), hi.max(l));
        sum += weight * value[c];
    }
    (hi - lo <= threshold * luminance(sum)).then_some(sum)
}
