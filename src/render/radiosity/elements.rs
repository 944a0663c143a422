//! The element atlas: every patch (a side of a diffuse primitive) is the
//! root of a quadtree whose leaves are res x res tiles of elements (Coombe
//! and Harris 39.3.1), laid out by the primitive's parameterisation. A tile
//! at depth d covers a (1/2^d)-square of the patch's (u, v) square, its
//! element (i, j) being cell (origin + (i, j)) of the patch's grid at
//! res 2^d cells a side. Splitting a leaf gives four children at depth d + 1
//! and retires it (its elements' areas become 0). The atlas has room for
//! `capacity` tiles, made once.

use glam::Vec3;

use crate::error::Error;
use crate::gpu::Result;
use crate::layout::CURVED_OUTLINE_SEGMENTS;
use crate::scene::{Geometry, Material, Scene};

/// Texels an element atlas may hold (each of its textures is RGBA32F:
/// 256 MiB apiece at this size).
pub const MAX_ATLAS_TEXELS: u64 = 1 << 24;

/// One side of a primitive: the root of a quadtree of tiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    pub primitive: usize,
    /// 0: the side the geometric normal points to; 1: the other.
    pub side: u32,
    pub emitter: bool,
}

/// A leaf of a patch's quadtree (or a retired one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tile {
    pub patch: u32,
    pub depth: u32,
    /// Its first cell on the patch's grid of res 2^depth cells a side.
    pub origin: [u32; 2],
    /// False once split (its elements then have area 0).
    pub alive: bool,
}

/// A quadtree node (`Elements::nodes`): a leaf's tile, an empty leaf (a
/// triangle's quarter beyond its diagonal), or four children from `first`,
/// in the order (0, 0), (1, 0), (0, 1), (1, 1) of (u, v) halves. Stored as
/// one i32 a node for glsl/radiosity/lookup.frag: t >= 0, -1, -(first + 2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Node {
    Leaf(usize),
    Empty,
    Split(usize),
}

impl Node {
    pub fn encode(self) -> i32 {
        match self {
            Node::Leaf(t) => t as i32,
            Node::Empty => -1,
            Node::Split(first) => -(first as i32) - 2,
        }
    }
}

/// The element atlas, as made on the CPU and kept in step with the GPU's.
pub struct Elements {
    pub patches: Vec<Patch>,
    pub tiles: Vec<Tile>,
    /// Node t stands where tile t does (patch p's root is node p; a split
    /// appends four nodes as it appends four tiles).
    pub nodes: Vec<Node>,
    pub res: u32,
    /// Tiles the atlas has room for.
    pub capacity: u32,
    pub tile_columns: u32,
    pub width: u32,
    pub height: u32,
    /// Per texel: position + area (0: no element), normal + patch, albedo, initial residual.
    pub position: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
    pub albedo: Vec<[f32; 4]>,
    pub emission: Vec<[f32; 4]>,
    /// Patch of (2 primitive + side), or -1.
    pub patch_of: Vec<i32>,
    /// Elements of live tiles.
    pub elements: usize,
}

/// Tiles of a full quadtree of depth `depth` (1 + 4 + ... + 4^depth).
pub fn full_tree(depth: u32) -> u64 {
    (4u64.pow(depth + 1) - 1) / 3
}

/// The point and outward normal of `g` at parameters (u, v) (the inverse of
/// glsl/radiosity/parameterisation.glsl's `patch_uv`).
pub fn element_point(g: &Geometry, u: f32, v: f32) -> (Vec3, Vec3) {
    use std::f32::consts::PI;
    match *g {
        Geometry::Sphere { center, radius } => {
            let (phi, theta) = (2.0 * PI * u, PI * v);
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            (center + radius * d, d)
        }
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            let (t, s) = crate::sampling::basis_around(axis);
            let phi = 2.0 * PI * u;
            let r = phi.cos() * t + phi.sin() * s;
            (base + radius * r + v * height * axis, r)
        }
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => (
            corner + u * edge1 + v * edge2,
            edge1.cross(edge2).normalize(),
        ),
        Geometry::Triangle { v0, v1, v2 } => (
            v0 + u * (v1 - v0) + v * (v2 - v0),
            (v1 - v0).cross(v2 - v0).normalize(),
        ),
    }
}

/// Cell (i, j)'s parameters on a grid of res cells a side: its cell's centre, or on a triangle's
/// diagonal the centroid of the half cell inside it (u + v < 1).
fn element_uv(g: &Geometry, i: u32, j: u32, res: u32) -> (f32, f32) {
    let n = res as f32;
    let third = matches!(g, Geometry::Triangle { .. }) && i + j + 1 == res;
    let c = if third { 1.0 / 3.0 } else { 0.5 };
    ((i as f32 + c) / n, (j as f32 + c) / n)
}

/// Segments around a sphere or cylinder in the item buffers' tessellation
/// (a sphere has half as many rows).
pub const CURVED_SEGMENTS: u32 = 32;

/// Where a sub-element shooter of a curved patch stands: its block's
/// centroid lies inside a sphere or cylinder, and would see the primitive's
/// inside, so it goes onto the surface and then, along its own normal n
/// (out for the outside patch, in for the inside one), twice the
/// tessellation's sagitta further, so that the facets nearest it are on the
/// side it shoots from. Planar shooters stay at their centroid.
pub fn onto_surface(g: &Geometry, p: Vec3, n: Vec3) -> Vec3 {
    let sagitta =
        |radius: f32| 2.0 * radius * (1.0 - (std::f32::consts::PI / CURVED_SEGMENTS as f32).cos());
    match *g {
        Geometry::Sphere { center, radius } => {
            center + radius * (p - center).normalize() + sagitta(radius) * n
        }
        Geometry::Cylinder {
            base, axis, radius, ..
        } => {
            let r = p - base;
            let along = r.dot(axis) * axis;
            base + along + radius * (r - along).normalize() + sagitta(radius) * n
        }
        _ => p,
    }
}

/// Whether a primitive is curved: its blocks' outlines follow the surface,
/// and its shooters stand at their area centroid moved onto it; a flat
/// one's stand at their power-weighted centre (shooters.frag).
pub fn is_curved(g: &Geometry) -> bool {
    matches!(g, Geometry::Sphere { .. } | Geometry::Cylinder { .. })
}

/// The outline on the surface of cells [i0, i1) x [j0, j1) of a grid of n
/// cells a side (a shooter's block): its corners on a parallelogram, the
/// part with u + v <= 1 on a triangle, and on a sphere or cylinder its four
/// edges along the surface in CURVED_OUTLINE_SEGMENTS each (a non-planar
/// loop: Lambert's formula gives the form factor of the surface it bounds).
/// Empty where the block holds no surface.
pub fn block_outline(g: &Geometry, [i0, j0, i1, j1]: [u32; 4], n: u32) -> Vec<Vec3> {
    let n = n as f32;
    let (u0, v0, u1, v1) = (i0 as f32 / n, j0 as f32 / n, i1 as f32 / n, j1 as f32 / n);
    let square = [(u0, v0), (u1, v0), (u1, v1), (u0, v1)];
    let mut uv: Vec<(f32, f32)> = square.to_vec();
    if is_curved(g) {
        let m = CURVED_OUTLINE_SEGMENTS;
        uv = (0..4)
            .flat_map(|edge| {
                let (a, b) = (square[edge], square[(edge + 1) % 4]);
                (0..m).map(move |s| {
                    let f = s as f32 / m as f32;
                    (a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1))
                })
            })
            .collect();
    }
    if matches!(g, Geometry::Triangle { .. }) {
        // Sutherland-Hodgman against u + v <= 1.
        let inside = |p: (f32, f32)| 1.0 - p.0 - p.1;
        let mut out = Vec::new();
        for k in 0..4 {
            let (a, b) = (square[k], square[(k + 1) % 4]);
            let (da, db) = (inside(a), inside(b));
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                let s = da / (da - db);
                out.push((a.0 + s * (b.0 - a.0), a.1 + s * (b.1 - a.1)));
            }
        }
        out.dedup();
        if out.len() > 1 && out.first() == out.last() {
            out.pop();
        }
        uv = out;
    }
    if uv.len() < 3 {
        return Vec::new();
    }
    let mut points: Vec<Vec3> = uv.iter().map(|&(u, v)| element_point(g, u, v).0).collect();
    // A sphere's pole is one point however many longitudes reach it.
    points.dedup_by(|a, b| a.distance_squared(*b) <= 1e-12 * b.length_squared());
    points
}

/// Cell (i, j)'s area on a grid of res x res cells, 0 where it holds none.
fn element_area(g: &Geometry, i: u32, j: u32, res: u32) -> f32 {
    use std::f32::consts::PI;
    let n = res as f32;
    match *g {
        Geometry::Sphere { radius, .. } => {
            let (t0, t1) = (PI * j as f32 / n, PI * (j + 1) as f32 / n);
            radius * radius * (t0.cos() - t1.cos()) * 2.0 * PI / n
        }
        Geometry::Triangle { .. } => {
            // Whole cells of the (u, v) grid inside u + v <= 1, and the half
            // cells along the diagonal: the triangle's area exactly.
            let whole = 2.0 * crate::scene::triangle_area(g) / (n * n);
            match (i + j + 1).cmp(&res) {
                std::cmp::Ordering::Less => whole,
                std::cmp::Ordering::Equal => 0.5 * whole,
                std::cmp::Ordering::Greater => 0.0,
            }
        }
        _ => crate::scene::surface_area(g) / (n * n),
    }
}

impl Elements {
    /// The atlas of `scene` at `res` elements a tile side, with room for
    /// every patch's quadtree to reach `max_depth` (as far as
    /// MAX_ATLAS_TEXELS and the driver's texture size allow: at least one
    /// tile a patch), or why it cannot be made.
    pub fn new(scene: &Scene, res: u32, max_depth: u32, max_side: u32) -> Result<Self> {
        let patches = scene
            .shapes
            .iter()
            .map(|s| match scene.materials[s.material] {
                Material::Diffuse { .. } => 2u64,
                Material::Emitter { .. } => 1,
                _ => 0,
            })
            .sum::<u64>()
            .max(1);
        let fits = |tiles: u64| {
            let columns = (tiles as f64).sqrt().ceil() as u64;
            let (w, h) = (columns * res as u64, tiles.div_ceil(columns) * res as u64);
            (
                w <= max_side as u64 && h <= max_side as u64 && w * h <= MAX_ATLAS_TEXELS,
                w,
                h,
            )
        };
        let (ok, w, h) = fits(patches);
        if !ok {
            return Err(Error::TooLarge(format!(
                "{patches} patches of {res} x {res} elements need an atlas of {w} x {h} texels; the limit is {max_side} a side and {MAX_ATLAS_TEXELS} in all: lower --elements (radiosity gives every side of every diffuse primitive its own tile, so large meshes do not fit)"
            )));
        }
        // Room to split: every tree full, or as many tiles as fit.
        let mut capacity = patches * full_tree(max_depth);
        while !fits(capacity).0 {
            capacity = (capacity * 7 / 8).max(patches);
        }
        Ok(Self::layout(scene, res, capacity as u32))
    }

    fn layout(scene: &Scene, res: u32, capacity: u32) -> Self {
        let mut patches = Vec::new();
        let mut patch_of = vec![-1i32; 2 * scene.shapes.len()];
        for (prim, shape) in scene.shapes.iter().enumerate() {
            match scene.materials[shape.material] {
                Material::Diffuse { .. } => {
                    for side in 0..2 {
                        patch_of[2 * prim + side as usize] = patches.len() as i32;
                        patches.push(Patch {
                            primitive: prim,
                            side,
                            emitter: false,
                        });
                    }
                }
                Material::Emitter { normal, .. } => {
                    let n = element_point(&shape.geometry, 0.5, 0.5).1;
                    let side = u32::from(normal.is_some_and(|e| e.dot(n) < 0.0));
                    patch_of[2 * prim + side as usize] = patches.len() as i32;
                    patches.push(Patch {
                        primitive: prim,
                        side,
                        emitter: true,
                    });
                }
                _ => {}
            }
        }
        let capacity = capacity.max(patches.len() as u32).max(1);
        let tile_columns = (capacity as f64).sqrt().ceil() as u32;
        let tile_rows = capacity.div_ceil(tile_columns);
        let (width, height) = (tile_columns * res, tile_rows * res);
        let texels = (width * height) as usize;
        let mut e = Elements {
            tiles: Vec::new(),
            nodes: Vec::new(),
            patches,
            res,
            capacity,
            tile_columns,
            width,
            height,
            position: vec![[0.0; 4]; texels],
            normal: vec![[0.0; 4]; texels],
            albedo: vec![[0.0; 4]; texels],
            emission: vec![[0.0; 4]; texels],
            patch_of,
            elements: 0,
        };
        for p in 0..e.patches.len() {
            e.nodes.push(Node::Leaf(p));
            e.tiles.push(Tile {
                patch: p as u32,
                depth: 0,
                origin: [0, 0],
                alive: true,
            });
            e.fill(scene, p);
        }
        e
    }

    /// Tile `t`'s first texel in the atlas.
    pub fn tile_base(&self, t: usize) -> (u32, u32) {
        let t = t as u32;
        (
            (t % self.tile_columns) * self.res,
            (t / self.tile_columns) * self.res,
        )
    }

    /// Tile `t`'s region of the atlas: x, y, width, height.
    pub fn tile_region(&self, t: usize) -> [i32; 4] {
        let (x, y) = self.tile_base(t);
        [x as i32, y as i32, self.res as i32, self.res as i32]
    }

    /// Atlas rows holding tiles so far (passes over the atlas draw these).
    pub fn rows_used(&self) -> u32 {
        (self.tiles.len() as u32).div_ceil(self.tile_columns) * self.res
    }

    /// Texel index of tile t's element (i, j).
    pub fn texel(&self, t: usize, i: u32, j: u32) -> usize {
        let (x, y) = self.tile_base(t);
        ((y + j) * self.width + x + i) as usize
    }

    /// Writes tile t's element records; returns how many elements it has.
    fn fill(&mut self, scene: &Scene, t: usize) -> usize {
        let tile = self.tiles[t];
        let patch = self.patches[tile.patch as usize];
        let shape = &scene.shapes[patch.primitive];
        let (albedo, emitted) = match scene.materials[shape.material] {
            Material::Diffuse { albedo } => (albedo, Vec3::ZERO),
            Material::Emitter { radiance, .. } => (Vec3::ZERO, std::f32::consts::PI * radiance),
            _ => (Vec3::ZERO, Vec3::ZERO),
        };
        let sign = if patch.side == 0 { 1.0 } else { -1.0 };
        let cells = self.res << tile.depth;
        let mut count = 0;
        for j in 0..self.res {
            for i in 0..self.res {
                let (ci, cj) = (tile.origin[0] + i, tile.origin[1] + j);
                let area = element_area(&shape.geometry, ci, cj, cells);
                let x = self.texel(t, i, j);
                if area <= 0.0 {
                    self.position[x] = [0.0; 4];
                    continue;
                }
                let (u, v) = element_uv(&shape.geometry, ci, cj, cells);
                let (point, normal) = element_point(&shape.geometry, u, v);
                self.position[x] = point.extend(area).to_array();
                self.normal[x] = (sign * normal).extend(tile.patch as f32).to_array();
                self.albedo[x] = albedo.extend(0.0).to_array();
                self.emission[x] = emitted.extend(0.0).to_array();
                count += 1;
            }
        }
        self.elements += count;
        count
    }

    /// Splits live tile `t` into its four children (retiring it), or None
    /// when the atlas is full. Returns the new tiles (children with no
    /// element, beyond a triangle's diagonal, get none).
    pub fn split(&mut self, scene: &Scene, t: usize) -> Option<Vec<usize>> {
        let parent = self.tiles[t];
        debug_assert!(parent.alive);
        if self.tiles.len() + 4 > self.capacity as usize {
            return None;
        }
        let first = self.nodes.len();
        self.nodes[t] = Node::Split(first);
        let mut made = Vec::new();
        for q in 0..4u32 {
            let origin = [
                2 * parent.origin[0] + (q % 2) * self.res,
                2 * parent.origin[1] + (q / 2) * self.res,
            ];
            let child = self.tiles.len();
            self.tiles.push(Tile {
                patch: parent.patch,
                depth: parent.depth + 1,
                origin,
                alive: true,
            });
            if self.fill(scene, child) > 0 {
                self.nodes.push(Node::Leaf(child));
                made.push(child);
            } else {
                self.nodes.push(Node::Empty);
                self.tiles[child].alive = false;
            }
        }
        self.tiles[t].alive = false;
        for j in 0..self.res {
            for i in 0..self.res {
                let x = self.texel(t, i, j);
                if self.position[x][3] > 0.0 {
                    self.elements -= 1;
                }
                self.position[x] = [0.0; 4];
            }
        }
        Some(made)
    }

    /// Tile t's `records` (position, normal, albedo or emission) in row order.
    pub fn tile_records(&self, t: usize, records: &[[f32; 4]]) -> Vec<f32> {
        let mut out = Vec::with_capacity((4 * self.res * self.res) as usize);
        for j in 0..self.res {
            for i in 0..self.res {
                out.extend_from_slice(&records[self.texel(t, i, j)]);
            }
        }
        out
    }

    /// The quadtree nodes as lookup.frag reads them.
    pub fn encoded_nodes(&self) -> Vec<i32> {
        self.nodes.iter().map(|n| n.encode()).collect()
    }

    /// Nodes the atlas's capacity can need: one a tile.
    pub fn node_capacity(&self) -> usize {
        self.capacity as usize
    }
}

/// A triangle's segments a side in the item buffers: as a parallelogram's
/// where the scene is small, so that its projected edges bend as
/// closely (coarser chords misplace the edges a receiver is seen across: a
/// closed box of triangles lost 1.2% of its power at 4); fewer as the
/// scene grows, at most TESSELLATED_TRIANGLES in all, and at least one.
fn triangle_segments(shapes: usize) -> u32 {
    let per_shape = TESSELLATED_TRIANGLES / shapes.max(1);
    (per_shape as f64)
        .sqrt()
        .floor()
        .clamp(1.0, f64::from(PLANAR_SEGMENTS)) as u32
}

/// The item buffers' triangles at most, from triangle primitives: as many
/// as 4096 triangles at 4 segments a side.
const TESSELLATED_TRIANGLES: usize = 65536;

/// A parallelogram's segments a side in the item buffers.
const PLANAR_SEGMENTS: u32 = 16;

/// Every primitive as triangles for the item buffers: (x, y, z, primitive)
/// a vertex. Planar shapes are subdivided, since the hemispherical projection
/// bends their edges.
pub fn tessellate(scene: &Scene) -> Vec<f32> {
    let mut out = Vec::new();
    let triangle_segments = triangle_segments(scene.shapes.len());
    for (prim, shape) in scene.shapes.iter().enumerate() {
        let g = &shape.geometry;
        let (nu, nv) = match g {
            Geometry::Sphere { .. } => (CURVED_SEGMENTS, CURVED_SEGMENTS / 2),
            Geometry::Cylinder { .. } => (CURVED_SEGMENTS, 4),
            Geometry::Parallelogram { .. } => (PLANAR_SEGMENTS, PLANAR_SEGMENTS),
            Geometry::Triangle { .. } => (triangle_segments, triangle_segments),
        };
        let triangle = matches!(g, Geometry::Triangle { .. });
        let at = |i: u32, j: u32| element_point(g, i as f32 / nu as f32, j as f32 / nv as f32).0;
        let mut push = |p: Vec3| out.extend([p.x, p.y, p.z, prim as f32]);
        for j in 0..nv {
            for i in 0..nu {
                if triangle {
                    // The lower-left triangles of the (u, v) grid inside u + v <= 1.
                    if i + j < nu {
                        push(at(i, j));
                        push(at(i + 1, j));
                        push(at(i, j + 1));
                    }
                    if i + j + 1 < nu {
                        push(at(i + 1, j));
                        push(at(i + 1, j + 1));
                        push(at(i, j + 1));
                    }
                    continue;
                }
                push(at(i, j));
                push(at(i + 1, j));
                push(at(i + 1, j + 1));
                push(at(i, j));
                push(at(i + 1, j + 1));
                push(at(i, j + 1));
            }
        }
    }
    out
}
