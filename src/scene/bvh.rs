//! A bounding volume hierarchy over every primitive of a scene (spheres,
//! cylinders, parallelograms and triangles alike, so every scene takes one
//! path), built on the CPU by the obvhs crate (PLOC, SAH reinsertion and leaf
//! collapse: `medium_build`, at most 4 primitives a leaf) and flattened for
//! the GPU: two integer texels a node, `(min bits, a)` and `(max bits, b)`. An
//! inner node's children are nodes `a` and `b`; a leaf holds `-b` primitives
//! from position `a` of `order`, which maps leaf order to primitive indices.
//! glsl/common/scene.glsl traverses it with an ordered stack of BVH_STACK
//! entries (near child first, the far one pushed with its entry distance), so
//! the tree must not be deeper; src/reference/bvh.rs is the twin.

use glam::{Vec3, Vec3A};

use super::{Geometry, Scene};
use crate::error::{Error, Result};

/// Leaves hold at most this many primitives (4 and 8 cost the same on llvmpipe; 1 is 30% slower).
pub const MAX_LEAF_PRIMITIVES: u32 = 4;

/// The flattened hierarchy.
#[derive(Clone, Debug, Default)]
pub struct FlatBvh {
    /// Per node: min.xyz and max.xyz as f32 bits, then a and b (see the module doc).
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
    /// Inner: the first child; leaf: the first position in `order`.
    pub a: i32,
    /// Inner: the second child; leaf: minus the primitive count.
    pub b: i32,
}

impl FlatNode {
    pub fn is_leaf(&self) -> bool {
        self.b < 0
    }

    /// The two texels of the node, as the GPU reads them (RGBA32I).
    pub fn texels(&self) -> [i32; 8] {
        let bits = |v: f32| v.to_bits() as i32;
        [
            bits(self.min.x),
            bits(self.min.y),
            bits(self.min.z),
            self.a,
            bits(self.max.x),
            bits(self.max.y),
            bits(self.max.z),
            self.b,
        ]
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

/// Builds and flattens the hierarchy over the scene's primitives; refuses a
/// tree deeper than the GPU's traversal stack.
pub fn build(scene: &Scene) -> Result<FlatBvh> {
    if scene.shapes.is_empty() {
        // One empty leaf whose box nothing meets.
        return Ok(FlatBvh {
            nodes: vec![FlatNode {
                min: Vec3::splat(f32::INFINITY),
                max: Vec3::splat(f32::NEG_INFINITY),
                a: 0,
                b: 0,
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
    let nodes: Vec<FlatNode> = bvh
        .nodes
        .iter()
        .map(|n| {
            let (a, b) = if n.prim_count > 0 {
                (n.first_index as i32, -(n.prim_count as i32))
            } else {
                (n.first_index as i32, n.first_index as i32 + 1)
            };
            FlatNode {
                min: Vec3::from(n.aabb.min),
                max: Vec3::from(n.aabb.max),
                a,
                b,
            }
        })
        .collect();
    let depth = depth_of(&nodes);
    let stack = crate::layout::BVH_STACK as u32;
    if depth > stack {
        return Err(Error::TooLarge(format!(
            "the scene's bounding volume hierarchy is {depth} levels deep; the GPU's traversal stack holds {stack}"
        )));
    }
    Ok(FlatBvh {
        nodes,
        order: bvh.primitive_indices,
        depth,
    })
}

/// Levels of the tree from node 0.
fn depth_of(nodes: &[FlatNode]) -> u32 {
    let mut deepest = 0;
    let mut pending = vec![(0usize, 1u32)];
    while let Some((i, d)) = pending.pop() {
        deepest = deepest.max(d);
        let n = nodes[i];
        if !n.is_leaf() {
            pending.push((n.a as usize, d + 1));
            pending.push((n.b as usize, d + 1));
        }
    }
    deepest
}

#[cfg(test)]
mod tests {
    use super::*;

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
