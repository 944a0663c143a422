//! The twin of glsl/render/sppm_update.frag: one pixel's gather at its visible
//! point and the update of its radius, count and flux, over a photon map read
//! back from the GPU, in the shader's order.

use glam::{IVec3, Vec3};

use crate::render::software::CpuPhotonMap;

/// One pixel's SPPM statistics: tau (rgb), R^2, direct-light sum (rgb), N.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelState {
    pub tau: Vec3,
    pub radius2: f32,
    pub direct: Vec3,
    pub count: f32,
}

/// A pixel's visible point in one iteration.
#[derive(Clone, Copy, Debug)]
pub struct VisiblePoint {
    pub position: Vec3,
    /// The surface normal on the side the eye sees.
    pub normal: Vec3,
    pub albedo: Vec3,
    /// The eye path's weight up to the point.
    pub throughput: Vec3,
}

/// Photons within `radius2` of the point that arrive on its visible side and
/// that `accept` (the leak tests) lets through: (power summed, photons
/// counted with their cell's weight).
pub fn gather(
    map: &CpuPhotonMap,
    x: Vec3,
    normal: Vec3,
    radius2: f32,
    accept: &dyn Fn(Vec3) -> bool,
) -> (Vec3, f32) {
    let g = &map.grid;
    let (res, cell_size) = (g.sides(), g.cell_size());
    let r = radius2.sqrt();
    let lo = ((x - r - g.min) / cell_size)
        .floor()
        .as_ivec3()
        .clamp(IVec3::ZERO, res - 1);
    let hi = ((x + r - g.min) / cell_size)
        .floor()
        .as_ivec3()
        .clamp(IVec3::ZERO, res - 1);
    let (mut power, mut m) = (Vec3::ZERO, 0.0f32);
    for cz in lo.z..=hi.z {
        for cy in lo.y..=hi.y {
            for cx in lo.x..=hi.x {
                let cell = (cx + res.x * (cy + res.y * cz)) as u32;
                for (slot, k, (p, w)) in map.cell_photons(cell) {
                    let offset = *p - x;
                    if offset.dot(offset) >= radius2 {
                        continue;
                    }
                    if map.incoming[slot][k].dot(normal) >= 0.0 || !accept(*p) {
                        continue;
                    }
                    power += *w;
                    m += map.weights[slot][k];
                }
            }
        }
    }
    (power, m)
}

/// One iteration at one pixel: add the iteration's direct light, gather at the
/// visible point (if any) and update N, R^2 and tau with `alpha`. A pixel that
/// has gathered nothing yet takes its radius as at most `first_radius2`.
/// `accept` gets the visible point and a photon position (the leak tests).
pub fn update(
    map: &CpuPhotonMap,
    state: PixelState,
    direct: Vec3,
    vp: Option<VisiblePoint>,
    alpha: f32,
    first_radius2: f32,
    accept: &dyn Fn(&VisiblePoint, Vec3) -> bool,
) -> PixelState {
    let mut s = state;
    s.direct += direct;
    let Some(vp) = vp else {
        return s;
    };
    let mut r2 = if s.count > 0.0 {
        s.radius2
    } else {
        s.radius2.min(first_radius2)
    };
    let (power, m) = gather(map, vp.position, vp.normal, r2, &|p| accept(&vp, p));
    if m > 0.0 {
        let phi = vp.throughput * (vp.albedo / std::f32::consts::PI) * power;
        let g = (s.count + alpha * m) / (s.count + m);
        s.tau = (s.tau + phi) * g;
        r2 *= g;
        s.count += alpha * m;
    }
    s.radius2 = r2;
    s
}
