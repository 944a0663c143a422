//! The BVH traversal of glsl/common/scene.glsl in Rust, step for step: the
//! same ordered stack, the same conservative box test and the same primitive
//! tests, so its answers are the GPU's (tests/gpu/bvh.rs compares both with a loop
//! over every primitive).

use glam::Vec3;

use crate::layout::BOX_ROBUST;
use crate::scene::bvh::FlatBvh;
use crate::scene::Scene;

use super::intersect::{intersect_geometry_ray, ShearedRay};

/// Entry distance into the box, or None.
pub fn box_entry(lo: Vec3, hi: Vec3, r: &ShearedRay, t_max: f32) -> Option<f32> {
    let t0 = (lo - r.o) * r.inv;
    let t1 = (hi - r.o) * r.inv;
    let (near, far) = (t0.min(t1), t0.max(t1));
    let t_in = near.x.max(near.y).max(near.z.max(0.0));
    let t_out = far.x.min(far.y).min(far.z) * BOX_ROBUST;
    (t_in <= t_out.min(t_max)).then_some(t_in)
}

/// What `bvh_trace` returns: the primitive and its (t, u, v).
pub type BvhHit = Option<(usize, (f32, f32, f32))>;

/// The closest hit before `t_max` (with `any_hit`, the first found).
pub fn trace(scene: &Scene, bvh: &FlatBvh, r: &ShearedRay, t_max: f32, any_hit: bool) -> BvhHit {
    let root = bvh.nodes.first()?;
    box_entry(root.min, root.max, r, t_max)?;
    let mut best_t = t_max;
    let mut hit: BvhHit = None;
    let (mut a, mut b) = (root.a, root.b);
    let mut stack: Vec<((i32, i32), f32)> = Vec::new();
    loop {
        if b < 0 {
            for i in a..a - b {
                let prim = bvh.order[i as usize] as usize;
                if let Some(h) = intersect_geometry_ray(&scene.shapes[prim].geometry, r) {
                    if h.0 < best_t {
                        best_t = h.0;
                        hit = Some((prim, h));
                    }
                }
            }
            if any_hit && hit.is_some() {
                return hit;
            }
        } else {
            let (l, rr) = (bvh.nodes[a as usize], bvh.nodes[b as usize]);
            let tl = box_entry(l.min, l.max, r, best_t);
            let tr = box_entry(rr.min, rr.max, r, best_t);
            let first = match (tl, tr) {
                (Some(tl), Some(tr)) => {
                    let (near, far, t_far) = if tr < tl { (rr, l, tl) } else { (l, rr, tr) };
                    stack.push(((far.a, far.b), t_far));
                    Some(near)
                }
                (Some(_), None) => Some(l),
                (None, Some(_)) => Some(rr),
                (None, None) => None,
            };
            if let Some(n) = first {
                (a, b) = (n.a, n.b);
                continue;
            }
        }
        while stack.last().is_some_and(|e| e.1 >= best_t) {
            stack.pop();
        }
        let Some(((na, nb), _)) = stack.pop() else {
            break;
        };
        (a, b) = (na, nb);
    }
    hit
}

/// Closest hit along a unit direction.
pub fn closest_hit(scene: &Scene, bvh: &FlatBvh, o: Vec3, d: Vec3) -> BvhHit {
    trace(scene, bvh, &ShearedRay::new(o, d), 1e30, false)
}

/// Whether anything blocks o toward o + t_max d.
pub fn occluded(scene: &Scene, bvh: &FlatBvh, o: Vec3, d: Vec3, t_max: f32) -> bool {
    trace(scene, bvh, &ShearedRay::new(o, d), t_max, true).is_some()
}
