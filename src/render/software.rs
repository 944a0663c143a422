//! The paper's software column (figure 7c): the same eye paths and photons
//! as a GPU render, with the radiance estimate on the CPU by a classic Jensen
//! photon map (a balanced kd-tree searched for the k nearest with a max-heap).

use glam::Vec3;

use crate::photon::{Grid, PhotonMap};
use crate::scene::{Material, Scene};

use super::{DirectLight, Image, RenderOutput};

/// A photon map read back from the GPU: per cell, its photons in the GPU's order.
pub struct CpuPhotonMap {
    pub grid: Grid,
    /// Per slot (a cell, or a hash bucket: `Grid::slot_of_cell`):
    /// (position, power) of each photon, in the GPU's order.
    pub cells: Vec<Vec<(Vec3, Vec3)>>,
    /// Per slot: each photon's direction of arrival, in the same order.
    pub incoming: Vec<Vec<Vec3>>,
    /// Per slot: how many photons each stored one stands for (1 in the sorted
    /// map; destined / kept of its cell in stencil routing).
    pub weights: Vec<Vec<f32>>,
}

impl CpuPhotonMap {
    pub fn from_gpu(map: &PhotonMap) -> Self {
        let (pos, pow, inc, texels, weights) = match map {
            PhotonMap::Sorted(m) => {
                let first: Vec<i32> = m.grid_first.read_i32().chunks(4).map(|c| c[0]).collect();
                let texels: Vec<Vec<usize>> = (0..m.grid.slot_count() as usize)
                    .map(|c| (first[c]..first[c + 1]).map(|i| i as usize).collect())
                    .collect();
                let weights = texels.iter().map(|t| vec![1.0; t.len()]).collect();
                (&m.position, &m.power, &m.incoming, texels, weights)
            }
            PhotonMap::Routed(m) => {
                let counts = m.counts.read_f32();
                let (b, w) = (m.block as usize, m.position.width as usize);
                let cells = m.grid.slot_count() as usize;
                let texels: Vec<Vec<usize>> = (0..cells)
                    .map(|c| {
                        let n = (counts[4 * c] as usize).min(b * b);
                        let (bx, by) =
                            (c % m.blocks_per_row as usize, c / m.blocks_per_row as usize);
                        (0..n)
                            .map(|k| {
                                let slot = b * b - 1 - k;
                                (by * b + slot / b) * w + bx * b + slot % b
                            })
                            .collect()
                    })
                    .collect();
                // Hashed: each photon's own factor (power .w); else the cell's.
                let power = m.grid.buckets().map(|_| m.power.read_f32());
                let weights = (0..cells)
                    .map(|c| {
                        let destined = counts[4 * c];
                        let cell = destined / destined.min((b * b) as f32).max(1.0);
                        let w = |&i: &usize| power.as_ref().map_or(cell, |p| p[4 * i + 3]);
                        texels[c].iter().map(w).collect()
                    })
                    .collect();
                (&m.position, &m.power, &m.incoming, texels, weights)
            }
        };
        let (pos, pow, inc) = (pos.read_f32(), pow.read_f32(), inc.read_f32());
        let v = |d: &[f32], i: usize| Vec3::from_slice(&d[4 * i..4 * i + 3]);
        Self {
            grid: *map.grid(),
            cells: texels
                .iter()
                .map(|c| c.iter().map(|&i| (v(&pos, i), v(&pow, i))).collect())
                .collect(),
            incoming: texels
                .iter()
                .map(|c| c.iter().map(|&i| v(&inc, i)).collect())
                .collect(),
            weights,
        }
    }

    pub fn photons(&self) -> impl Iterator<Item = &(Vec3, Vec3)> {
        self.cells.iter().flatten()
    }

    /// The photons of `cell` as (slot, index in the slot, photon): a hash
    /// bucket's photons of other cells are skipped (their cell recomputed
    /// from the position, as glsl/common/photon_map.glsl does).
    pub fn cell_photons(&self, cell: u32) -> impl Iterator<Item = (usize, usize, &(Vec3, Vec3))> {
        let slot = self.grid.slot_of_cell(cell) as usize;
        let hashed = self.grid.buckets().is_some();
        self.cells[slot]
            .iter()
            .enumerate()
            .filter(move |(_, (p, _))| !hashed || self.grid.cell_of(*p) == Some(cell))
            .map(move |(k, photon)| (slot, k, photon))
    }
}

/// The end state of one search.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct KnnResult {
    pub flux: Vec3,
    pub radius2: f32,
    pub accepted: u32,
}

impl KnnResult {
    /// Irradiance sum / (pi r^2), r the radius once k are in, else the maximum
    /// radius (glsl/render/compose.frag).
    pub fn irradiance(&self, k: u32, max_radius: f32) -> Vec3 {
        let r2 = if self.accepted >= k {
            self.radius2
        } else {
            max_radius * max_radius
        };
        if r2 > 0.0 {
            self.flux / (std::f32::consts::PI * r2)
        } else {
            Vec3::ZERO
        }
    }
}

/// A balanced kd-tree over photons (Jensen, "Realistic Image Synthesis Using
/// Photon Mapping", 2001): median splits on the widest axis, stored as a heap.
pub struct KdTree {
    nodes: Vec<(Vec3, Vec3, u8)>, // position, power, split axis (3 = leaf)
}

impl KdTree {
    pub fn new(photons: &[(Vec3, Vec3)]) -> Self {
        let mut items: Vec<(Vec3, Vec3)> = photons.to_vec();
        let mut nodes = Vec::with_capacity(items.len());
        fn build(items: &mut [(Vec3, Vec3)], nodes: &mut Vec<(Vec3, Vec3, u8)>) {
            if items.is_empty() {
                return;
            }
            let (mut lo, mut hi) = (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY));
            for (p, _) in items.iter() {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            let ext = hi - lo;
            let axis = if ext.x >= ext.y && ext.x >= ext.z {
                0
            } else if ext.y >= ext.z {
                1
            } else {
                2
            };
            let mid = items.len() / 2;
            items.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
            let (left, rest) = items.split_at_mut(mid);
            let (median, right) = rest.split_first_mut().expect("non-empty");
            nodes.push((
                median.0,
                median.1,
                if left.is_empty() && right.is_empty() {
                    3
                } else {
                    axis as u8
                },
            ));
            // Pre-order: the left subtree (len / 2 nodes) follows, then the right.
            build(left, nodes);
            build(right, nodes);
        }
        build(&mut items, &mut nodes);
        Self { nodes }
    }

    /// The k nearest photons within max_radius (a max-heap keyed on distance):
    /// (sum of their power, squared distance of the farthest, how many).
    pub fn k_nearest(&self, x: Vec3, k: usize, max_radius: f32) -> KnnResult {
        let mut heap: std::collections::BinaryHeap<(OrdF32, usize)> =
            std::collections::BinaryHeap::new();
        let mut bound = max_radius * max_radius;
        self.search(0, self.nodes.len(), x, k, &mut bound, &mut heap);
        let mut flux = Vec3::ZERO;
        let mut r2 = 0f32;
        for (d2, i) in &heap {
            flux += self.nodes[*i].1;
            r2 = r2.max(d2.0);
        }
        KnnResult {
            flux,
            radius2: r2,
            accepted: heap.len() as u32,
        }
    }

    /// Searches the pre-order subtree nodes[start..end] (root at start, left
    /// subtree next with (len - 1) / 2 nodes, then the right subtree).
    fn search(
        &self,
        start: usize,
        end: usize,
        x: Vec3,
        k: usize,
        bound: &mut f32,
        heap: &mut std::collections::BinaryHeap<(OrdF32, usize)>,
    ) {
        if start >= end {
            return;
        }
        let len = end - start;
        let left_len = len / 2;
        let (p, _, axis) = self.nodes[start];
        let (l0, l1) = (start + 1, start + 1 + left_len);
        let (r0, r1) = (l1, end);
        if axis < 3 {
            let delta = x[axis as usize] - p[axis as usize];
            let (near, far) = if delta < 0.0 {
                ((l0, l1), (r0, r1))
            } else {
                ((r0, r1), (l0, l1))
            };
            self.search(near.0, near.1, x, k, bound, heap);
            if delta * delta <= *bound {
                self.search(far.0, far.1, x, k, bound, heap);
            }
        }
        let d2 = (p - x).length_squared();
        if d2 <= *bound {
            heap.push((OrdF32(d2), start));
            if heap.len() > k {
                heap.pop();
            }
            if heap.len() == k {
                *bound = heap.peek().map_or(*bound, |t| t.0 .0);
            }
        }
    }
}

#[derive(Clone, Copy, PartialEq, Debug)]
struct OrdF32(f32);
impl Eq for OrdF32 {}
impl PartialOrd for OrdF32 {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for OrdF32 {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// The software column with Jensen's kd-tree: exactly the k nearest photons.
pub fn software_image(out: &RenderOutput, scene: &Scene) -> Option<Image> {
    let map = CpuPhotonMap::from_gpu(out.map()?);
    let photons: Vec<(Vec3, Vec3)> = map.photons().copied().collect();
    let tree = KdTree::new(&photons);
    let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
    Some(software_image_with(&out.state.direct, scene, &|x| {
        tree.k_nearest(x, k as usize, max_r)
    }))
}

/// The software column with any CPU search at each first diffuse hit: the
/// GPU's direct light plus throughput x albedo/pi x the search's irradiance.
/// Two threads of rows.
pub fn software_image_with(
    direct_light: &DirectLight,
    scene: &Scene,
    search: &(dyn Fn(Vec3) -> KnnResult + Sync),
) -> Image {
    let (w, h) = (direct_light.radiance.width, direct_light.radiance.height);
    let direct = direct_light.radiance.read_f32();
    let pos = direct_light.diffuse_position.read_f32();
    let normal = direct_light.diffuse_normal.read_f32();
    let through = direct_light.diffuse_throughput.read_f32();
    let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
    let mut rgba = vec![0f32; (w * h * 4) as usize];
    let shade = |i: usize| -> [f32; 3] {
        let mut l = Vec3::from_slice(&direct[4 * i..4 * i + 3]);
        let mat = normal[4 * i + 3] as i32 - 1;
        if pos[4 * i + 3] > 0.0 && mat >= 0 {
            if let Material::Diffuse { albedo } = scene.materials[mat as usize] {
                let x = Vec3::from_slice(&pos[4 * i..4 * i + 3]);
                let e = search(x).irradiance(k, max_r);
                l += Vec3::from_slice(&through[4 * i..4 * i + 3]) * albedo / std::f32::consts::PI
                    * e;
            }
        }
        l.to_array()
    };
    let half = (w * h / 2) as usize;
    let (a, b) = rgba.split_at_mut(half * 4);
    std::thread::scope(|s| {
        s.spawn(|| {
            for (j, px) in a.chunks_mut(4).enumerate() {
                px[..3].copy_from_slice(&shade(j));
            }
        });
        for (j, px) in b.chunks_mut(4).enumerate() {
            px[..3].copy_from_slice(&shade(half + j));
        }
    });
    Image::from_gl_rgba(w, h, &rgba)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kd_tree_finds_the_same_k_nearest_as_brute_force() {
        let mut state = 7u32;
        let mut next = || crate::random::rng_next(&mut state);
        let photons: Vec<(Vec3, Vec3)> = (0..3000)
            .map(|_| (Vec3::new(next(), next() * 0.2, next()), Vec3::splat(next())))
            .collect();
        let tree = KdTree::new(&photons);
        for _ in 0..200 {
            let x = Vec3::new(next(), next() * 0.2, next());
            for (k, r) in [(1usize, 1.0f32), (20, 1.0), (50, 0.05)] {
                let got = tree.k_nearest(x, k, r);
                let mut d: Vec<(f32, Vec3)> = photons
                    .iter()
                    .map(|(p, w)| ((*p - x).length_squared(), *w))
                    .filter(|(d, _)| *d <= r * r)
                    .collect();
                d.sort_by(|a, b| a.0.total_cmp(&b.0));
                d.truncate(k);
                assert_eq!(got.accepted as usize, d.len());
                let flux: Vec3 = d.iter().map(|(_, w)| *w).sum();
                assert!(
                    (got.flux - flux).abs().max_element() < 1e-4,
                    "{:?} vs {flux}",
                    got.flux
                );
                assert_eq!(got.radius2, d.last().map_or(0.0, |t| t.0));
            }
        }
    }
}
