//! The BVH traversal of glsl/common/scene.glsl in Rust, step for step: the
//! same two walks over the threaded layout (the ordered one with its stack,
//! and the threaded one of a hierarchy in a uniform block), the same
//! conservative box test and the same primitive tests, so its answers are
//! the GPU's (tests/gpu/bvh.rs compares them with a loop over every
//! primitive).

use glam::Vec3;

use crate::layout::BOX_ROBUST;
use crate::scene::bvh::{FlatBvh, FlatNode};
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

/// Tests a leaf's primitives, keeping the closest hit before `best_t`.
fn leaf(
    scene: &Scene,
    bvh: &FlatBvh,
    n: &FlatNode,
    r: &ShearedRay,
    best_t: &mut f32,
    hit: &mut BvhHit,
) {
    for i in n.first..n.first + n.count {
        let prim = bvh.order[i as usize] as usize;
        if let Some(h) = intersect_geometry_ray(&scene.shapes[prim].geometry, r) {
            if h.0 < *best_t {
                *best_t = h.0;
                *hit = Some((prim, h));
            }
        }
    }
}

/// The closest hit before `t_max` (with `any_hit`, the first found) by the
/// ordered walk: an inner node's children are the next node and its miss
/// link, the nearer entered first, the farther stacked with its entry.
pub fn trace(scene: &Scene, bvh: &FlatBvh, r: &ShearedRay, t_max: f32, any_hit: bool) -> BvhHit {
    let root = bvh.nodes.first()?;
    box_entry(root.min, root.max, r, t_max)?;
    let mut best_t = t_max;
    let mut hit: BvhHit = None;
    let mut node = 0usize;
    let mut stack: Vec<(usize, f32)> = Vec::new();
    loop {
        let n = bvh.nodes[node];
        if n.is_leaf() {
            leaf(scene, bvh, &n, r, &mut best_t, &mut hit);
            if any_hit && hit.is_some() {
                return hit;
            }
        } else {
            let a = node + 1;
            let b = bvh.nodes[a].miss as usize;
            let (l, rr) = (bvh.nodes[a], bvh.nodes[b]);
            let tl = box_entry(l.min, l.max, r, best_t);
            let tr = box_entry(rr.min, rr.max, r, best_t);
            let first = match (tl, tr) {
                (Some(tl), Some(tr)) => {
                    let (near, far, t_far) = if tr < tl { (b, a, tl) } else { (a, b, tr) };
                    stack.push((far, t_far));
                    Some(near)
                }
                (Some(_), None) => Some(a),
                (None, Some(_)) => Some(b),
                (None, None) => None,
            };
            if let Some(next) = first {
                node = next;
                continue;
            }
        }
        while stack.last().is_some_and(|e| e.1 >= best_t) {
            stack.pop();
        }
        let Some((next, _)) = stack.pop() else {
            break;
        };
        node = next;
    }
    hit
}

/// The same by the threaded walk (SCENE_BVH_BLOCK): a node whose box the
/// ray enters leads to the next node (a leaf after testing its primitives,
/// to its miss link), a missed one to its miss link.
pub fn trace_threaded(
    scene: &Scene,
    bvh: &FlatBvh,
    r: &ShearedRay,
    t_max: f32,
    any_hit: bool,
) -> BvhHit {
    let mut best_t = t_max;
    let mut hit: BvhHit = None;
    let mut node = if bvh.nodes.is_empty() { -1 } else { 0 };
    while node >= 0 {
        let n = bvh.nodes[node as usize];
        let enter = box_entry(n.min, n.max, r, best_t).is_some();
        if enter && n.is_leaf() {
            leaf(scene, bvh, &n, r, &mut best_t, &mut hit);
            if any_hit && hit.is_some() {
                return hit;
            }
        }
        node = if enter && !n.is_leaf() {
            node + 1
        } else {
            n.miss
        };
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
