//! Instant global illumination's gather on the CPU, the twin of
//! glsl/render/igi_gather.frag (without interleaving or downsampling): the
//! incident light at x from every VPL, with the bounded geometry term and a
//! shadow ray each, exact (against the primitives) or imperfect (against
//! their bounding boxes, passed through with both ends outside).

use glam::Vec3;

use super::intersect::intersect_geometry;
use super::ray_trace::offset_scale;
use crate::scene::Scene;

/// One virtual point light: position, normal (facing where its light came
/// from), intensity (power x albedo / pi).
#[derive(Clone, Copy, Debug)]
pub struct Vpl {
    pub position: Vec3,
    pub normal: Vec3,
    pub intensity: Vec3,
}

/// Marques and Santos's f(0.8 m, 1.2 m, d), quadratic between; 1 when m = 0.
pub fn bound(d: f32, m: f32) -> f32 {
    if m <= 0.0 {
        return 1.0;
    }
    let s = ((d - 0.8 * m) / (0.4 * m)).clamp(0.0, 1.0);
    s * s
}

/// Whether a primitive's bounding box blocks the segment from o along unit
/// d to t_max: passed through with both ends outside.
fn box_blocks(lo: Vec3, hi: Vec3, o: Vec3, d: Vec3, t_max: f32) -> bool {
    let inv = d.recip();
    let (t0, t1) = ((lo - o) * inv, (hi - o) * inv);
    let (near, far) = (t0.min(t1), t0.max(t1));
    let (t_in, t_out) = (near.max_element(), far.min_element());
    t_in > 0.0 && t_in <= t_out && t_out < t_max
}

fn occluded(scene: &Scene, o: Vec3, d: Vec3, t_max: f32, boxes: bool) -> bool {
    scene.shapes.iter().any(|s| {
        if boxes {
            let (lo, hi) = crate::scene::bvh::bounds(&s.geometry);
            box_blocks(lo, hi, o, d, t_max)
        } else {
            intersect_geometry(&s.geometry, o, d).is_some_and(|h| h.0 < t_max)
        }
    })
}

/// The incident light at x (normal nx, facing the viewer) from `vpls`.
pub fn incident(
    scene: &Scene,
    vpls: &[Vpl],
    x: Vec3,
    nx: Vec3,
    min_distance: f32,
    imperfect: bool,
) -> Vec3 {
    let floor = 1e-6 * scene.size();
    let mut sum = Vec3::ZERO;
    for v in vpls {
        let to = v.position - x;
        let d2 = to.length_squared();
        if d2 <= 0.0 {
            continue;
        }
        let d = d2.sqrt();
        let w = to / d;
        let (cos_x, cos_y) = (nx.dot(w), -v.normal.dot(w));
        if cos_x <= 0.0 || cos_y <= 0.0 {
            continue;
        }
        let g = cos_x * cos_y / d2 * bound(d, min_distance);
        if g <= 0.0 {
            continue;
        }
        let s = offset_scale(x, floor);
        let origin = x + if w.dot(nx) >= 0.0 { s } else { -s } * nx;
        let to_y = v.position - origin;
        let reach = to_y.length();
        let t_max = reach - 2.0 * offset_scale(v.position, floor);
        if occluded(scene, origin, to_y / reach, t_max, imperfect) {
            continue;
        }
        sum += v.intensity * g;
    }
    sum
}
