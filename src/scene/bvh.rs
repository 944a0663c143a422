//! A bounding volume hierarchy over every primitive of a scene (spheres,
//! cylinders, parallelograms and triangles alike, so every scene takes one
//! path), built on the CPU by the obvhs crate (PLOC, SAH reinsertion and leaf
//! collapse: `medium_build`, at most 4 primitives a leaf) and flattened for
//! the GPU, threaded (Smits 1998): the nodes in depth-first order, each with
//! its miss link, the node that follows its subtree. A ray that enters a
//! node's box goes on to the next node (an inner node's first child; a leaf
//! tests its primitives and goes to its miss link); one that misses it goes
//! to its miss link; -1 ends the walk. That walk needs no stack; the ordered
//! walk finds an inner node's children at the next node and at that one's
//! miss link, and enters the nearer first with a stack of BVH_STACK entries,
//! so the tree must not be deeper. glsl/common/scene.glsl walks it either
//! way (by where the hierarchy lives); src/twins/bvh.rs holds both walks.

use glam::{Vec3, Vec3A};

use super::{Geometry, Scene};
use crate::error::{Error, Result};
use crate::layout::LEAF_COUNT_SPAN;

/// Leaves hold at most this many primitives (4 and 8 cost the same on llvmpipe; 1 is 30% slower).
pub const MAX_LEAF_PRIMITIVES: u32 = 4;
const _: () = assert!(MAX_LEAF_PRIMITIVES < LEAF_COUNT_SPAN as u32);

/// What one ray's box test costs, in tests of one primitive, and what a walk
/// costs before its first test (the loop it runs, its node fetches): fitted
/// on llvmpipe to three scenes whose two ways were timed against each other
/// (`results/llvmpipe/meshes/linear_scan.md`).
const BOX_TEST_COST: f32 = 1.8;
const WALK_FIXED_COST: f32 = 5.0;

/// The flattened hierarchy.
#[derive(Clone, Debug, Default)]
pub struct FlatBvh {
    /// The nodes in depth-first order (see the module doc).
    pub nodes: Vec<FlatNode>,
    /// Leaf order -> primitive index.
    pub order: Vec<u32>,
    /// Nodes on the longest path from the root, the root included.
    pub depth: u32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlatNode {
    pub min: Vec3,
    pub max: Vec3,
    /// A leaf's first position in `order` (0 for an inner node).
    pub first: u32,
    /// A leaf's primitives; 0: an inner node, whose first child is the next node.
    pub count: u32,
    /// The node after this one's subtree in depth-first order; -1: none.
    pub miss: i32,
}

impl FlatNode {
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }

    /// The two texels of the node, as the GPU reads them (RGBA32I):
    /// `(min bits, leaf)` and `(max bits, miss)`, where leaf is
    /// -(first x LEAF_COUNT_SPAN + count) for a leaf and 0 for an inner node.
    pub fn texels(&self) -> [i32; 8] {
        let bits = |v: f32| v.to_bits() as i32;
        let leaf = if self.is_leaf() {
            -(self.first as i32 * LEAF_COUNT_SPAN + self.count as i32)
        } else {
            0
        };
        [
            bits(self.min.x),
            bits(self.min.y),
            bits(self.min.z),
            leaf,
            bits(self.max.x),
            bits(self.max.y),
            bits(self.max.z),
            self.miss,
        ]
    }
}

impl FlatBvh {
    /// One ray's expected work in the walk, in primitive tests, by the
    /// surface area heuristic (MacDonald and Booth 1990): a node's box is
    /// tested by the rays that enter its parent, a leaf's primitives by the
    /// rays that enter the leaf, and a ray enters a box with the chance of
    /// its surface area over the root's.
    pub fn walk_cost(&self) -> f32 {
        let area = |n: &FlatNode| {
            obvhs::aabb::Aabb {
                min: Vec3A::from(n.min),
                max: Vec3A::from(n.max),
            }
            .half_area()
        };
        let root = area(&self.nodes[0]);
        // An empty scene's box is inverted; a degenerate one has no area.
        if !(root.is_finite() && root > 0.0) {
            return WALK_FIXED_COST;
        }
        let mut cost = WALK_FIXED_COST + BOX_TEST_COST;
        for n in &self.nodes {
            let entered = area(n) / root;
            if n.is_leaf() {
                cost += entered * n.count as f32;
            } else {
                cost += entered * 2.0 * BOX_TEST_COST;
            }
        }
        cost
    }

    /// Whether a loop over every one of the scene's `primitives` traces
    /// faster than this hierarchy's walk (and the primitives fit the loop's
    /// uniform block, `LINEAR_SCAN_MAX`). A closed room's walls fill their
    /// boxes, so a box culls little there; a small mesh in a large room is
    /// culled whole by one.
    pub fn loses_to_a_loop(&self, primitives: usize) -> bool {
        primitives <= crate::layout::LINEAR_SCAN_MAX && (primitives as f32) < self.walk_cost()
    }
}

/// The box of one primitive.
pub fn bounds(g: &Geometry) -> (Vec3, Vec3) {
    match *g {
        Geometry::Sphere { center, radius } => (center - radius, center + radius),
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            let top = base + axis * height;
            // The disc's extent along each axis: r sqrt(1 - a_i^2).
            let e = (Vec3::ONE - axis * axis).max(Vec3::ZERO).powf(0.5) * radius;
            (base.min(top) - e, base.max(top) + e)
        }
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => {
            let c = [
                corner,
                corner + edge1,
                corner + edge2,
                corner + edge1 + edge2,
            ];
            (
                c.iter().fold(c[0], |m, p| m.min(*p)),
                c.iter().fold(c[0], |m, p| m.max(*p)),
            )
        }
        Geometry::Triangle { v0, v1, v2 } => (v0.min(v1).min(v2), v0.max(v1).max(v2)),
    }
}

/// Builds the hierarchy over the scene's primitives and threads it.
pub fn build(scene: &Scene) -> Result<FlatBvh> {
    if scene.shapes.is_empty() {
        // One node whose box nothing meets.
        return Ok(FlatBvh {
            nodes: vec![FlatNode {
                min: Vec3::splat(f32::INFINITY),
                max: Vec3::splat(f32::NEG_INFINITY),
                first: 0,
                count: 0,
                miss: -1,
            }],
            order: Vec::new(),
            depth: 1,
        });
    }
    let boxes: Vec<obvhs::aabb::Aabb> = scene
        .shapes
        .iter()
        .map(|s| {
            let (lo, hi) = bounds(&s.geometry);
            obvhs::aabb::Aabb {
                min: Vec3A::from(lo),
                max: Vec3A::from(hi),
            }
        })
        .collect();
    let mut params = obvhs::BvhBuildParams::medium_build();
    params.max_prims_per_leaf = MAX_LEAF_PRIMITIVES;
    let bvh = obvhs::bvh2::builder::build_bvh2(&boxes, params, &mut Default::default());
    let (nodes, depth) = thread(&bvh.nodes);
    let stack = crate::layout::BVH_STACK as u32;
    if depth > stack {
        return Err(Error::TooLarge(format!(
            "the scene's bounding volume hierarchy is {depth} levels deep; the GPU's traversal stack holds {stack}"
        )));
    }
    if nodes.len() >= (i32::MAX / LEAF_COUNT_SPAN) as usize {
        return Err(Error::TooLarge(format!(
            "{} hierarchy nodes: the GPU's node links hold at most {}",
            nodes.len(),
            i32::MAX / LEAF_COUNT_SPAN
        )));
    }
    Ok(FlatBvh {
        nodes,
        order: bvh.primitive_indices,
        depth,
    })
}

/// obvhs's nodes (an inner node's children at `first_index` and the one
/// after) in depth-first order with their miss links, and the tree's depth.
fn thread(tree: &[obvhs::bvh2::node::Bvh2Node]) -> (Vec<FlatNode>, u32) {
    // Pre-order, first child first: a node's subtree is the run of `size`
    // nodes from its place, so its miss link is place + size.
    let mut preorder = Vec::with_capacity(tree.len());
    let mut level = vec![0u32; tree.len()];
    level[0] = 1;
    let mut stack = vec![0usize];
    while let Some(i) = stack.pop() {
        preorder.push(i);
        let n = &tree[i];
        if n.prim_count == 0 {
            let first = n.first_index as usize;
            level[first] = level[i] + 1;
            level[first + 1] = level[i] + 1;
            stack.push(first + 1);
            stack.push(first);
        }
    }
    let mut size = vec![1usize; tree.len()];
    for &i in preorder.iter().rev() {
        let n = &tree[i];
        if n.prim_count == 0 {
            let first = n.first_index as usize;
            size[i] = 1 + size[first] + size[first + 1];
        }
    }
    let nodes = preorder
        .iter()
        .enumerate()
        .map(|(place, &i)| {
            let n = &tree[i];
            let after = place + size[i];
            FlatNode {
                min: Vec3::from(n.aabb.min),
                max: Vec3::from(n.aabb.max),
                first: if n.prim_count > 0 { n.first_index } else { 0 },
                count: n.prim_count,
                miss: if after < preorder.len() {
                    after as i32
                } else {
                    -1
                },
            }
        })
        .collect();
    let depth = preorder.iter().map(|&i| level[i]).max().unwrap_or(1);
    (nodes, depth)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_closed_room_takes_the_loop_and_a_small_mesh_in_the_open_the_walk() {
        // Two of the scenes the costs were fitted on, timed both ways
        // (results/llvmpipe/meshes/linear_scan.md).
        let room = crate::scene::embedded::load("cornell_box_obj").unwrap();
        assert_eq!(room.shapes.len(), 38);
        assert!(build(&room).unwrap().loses_to_a_loop(room.shapes.len()));
        let mut stage = crate::scene::embedded::load("variants/mesh_stage").unwrap();
        let at = stage
            .shapes
            .iter()
            .position(|s| matches!(s.geometry, Geometry::Sphere { .. }))
            .unwrap();
        let ball = stage.shapes.remove(at);
        let Geometry::Sphere { center, radius } = ball.geometry else {
            unreachable!()
        };
        let mesh = crate::scene::generate::uv_sphere(48, 0.0);
        stage
            .shapes
            .extend(mesh.shapes(ball.material, radius, center));
        assert_eq!(stage.shapes.len(), 27);
        let tree = build(&stage).unwrap();
        assert!(
            !tree.loses_to_a_loop(stage.shapes.len()),
            "{}",
            tree.walk_cost()
        );
        // Past the uniform block's room the loop is never taken.
        assert!(!tree.loses_to_a_loop(crate::layout::LINEAR_SCAN_MAX + 1));
    }

    #[test]
    fn a_cylinders_box_holds_its_rims() {
        let g = Geometry::Cylinder {
            base: Vec3::new(1.0, 2.0, 3.0),
            axis: Vec3::new(0.6, 0.8, 0.0),
            radius: 0.5,
            height: 2.0,
        };
        let (lo, hi) = bounds(&g);
        let (t, b) = crate::sampling::basis_around(Vec3::new(0.6, 0.8, 0.0));
        for k in 0..64 {
            let phi = k as f32 / 64.0 * std::f32::consts::TAU;
            for h in [0.0, 2.0] {
                let p = Vec3::new(1.0, 2.0, 3.0)
                    + Vec3::new(0.6, 0.8, 0.0) * h
                    + 0.5 * (phi.cos() * t + phi.sin() * b);
                assert!(p.cmpge(lo - 1e-5).all() && p.cmple(hi + 1e-5).all(), "{p}");
            }
        }
    }
}
