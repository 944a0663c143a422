//! The kNN-grid of glsl/render/knn_search.frag on the CPU, with the same
//! visiting order and acceptance rules, to test the GPU against; and the
//! software column computed with it or with the kd-tree.

use glam::Vec3;

use crate::render::software::{software_image as kd_tree_image, software_image_with};
pub use crate::render::software::{CpuPhotonMap, KdTree, KnnResult};

/// The kNN-grid search of section 2.3, in the GPU's order.
pub fn knn_grid(map: &CpuPhotonMap, x: Vec3, k: u32, max_radius: f32) -> KnnResult {
    knn_grid_filtered(map, x, k, max_radius, &|_| true)
}

/// Whether a photon at `p` may light query point `x` (normal `nf`): the twin
/// of glsl/common/visibility.glsl.
pub fn photon_visible(scene: &crate::scene::Scene, x: Vec3, nf: Vec3, p: Vec3) -> bool {
    use super::ray_trace::{occluded, offset_scale};
    let floor = 1e-6 * scene.size();
    let dist = x.distance(p);
    let a = x + nf * (0.1 * dist + offset_scale(x, floor));
    let b = p + nf * (0.1 * dist + offset_scale(p, floor));
    let d = b - a;
    let len = d.length();
    len <= 0.0 || !occluded(scene, a, d / len, 0.999 * len)
}

/// The same search, taking only photons (positions) that `accept` lets
/// through: the leak tests.
pub fn knn_grid_filtered(
    map: &CpuPhotonMap,
    x: Vec3,
    k: u32,
    max_radius: f32,
    accept: &dyn Fn(Vec3) -> bool,
) -> KnnResult {
    knn_grid_counted(map, x, k, max_radius, accept).0
}

/// The search and the photons it examined: every photon of every in-grid
/// cell on the shells it visits, the count the paper's search (the GPU's
/// `--paper-search`) keeps in its state.
pub fn knn_grid_counted(
    map: &CpuPhotonMap,
    x: Vec3,
    k: u32,
    max_radius: f32,
    accept: &dyn Fn(Vec3) -> bool,
) -> (KnnResult, u64) {
    let mut examined = 0u64;
    let g = &map.grid;
    let (res, cell_size) = (g.sides(), g.cell_size());
    let f = ((x - g.min) / cell_size).floor();
    let c0 = [0, 1, 2].map(|a| (f[a] as i32).clamp(0, res[a] - 1));
    let max_r2 = max_radius * max_radius;
    let (mut flux, mut r2, mut accepted) = (Vec3::ZERO, 0.0f32, 0u32);
    let mut ring = 0i32;
    loop {
        // Every cell of the shell at Chebyshev distance `ring`, z, then y, then x.
        for dz in -ring..=ring {
            let z = c0[2] + dz;
            if z < 0 || z >= res[2] {
                continue;
            }
            for dy in -ring..=ring {
                let y = c0[1] + dy;
                if y < 0 || y >= res[1] {
                    continue;
                }
                for dx in -ring..=ring {
                    if dx.abs() < ring && dy.abs() < ring && dz.abs() < ring {
                        continue;
                    }
                    let xi = c0[0] + dx;
                    if xi < 0 || xi >= res[0] {
                        continue;
                    }
                    let cell = (xi + res[0] * (y + res[1] * z)) as u32;
                    for (_, _, (p, power)) in map.cell_photons(cell) {
                        examined += 1;
                        let o = *p - x;
                        let d2 = o.dot(o);
                        if d2 <= max_r2 && (accepted < k || d2 <= r2) && accept(*p) {
                            flux += *power;
                            if accepted < k {
                                r2 = r2.max(d2);
                            }
                            accepted += 1;
                        }
                    }
                }
            }
        }
        let lo = g.min
            + Vec3::new(
                (c0[0] - ring) as f32,
                (c0[1] - ring) as f32,
                (c0[2] - ring) as f32,
            ) * cell_size;
        let hi = g.min
            + Vec3::new(
                (c0[0] + ring + 1) as f32,
                (c0[1] + ring + 1) as f32,
                (c0[2] + ring + 1) as f32,
            ) * cell_size;
        // A face on the grid's boundary bounds nothing: no photon lies beyond.
        let far = 3.0e38f32;
        let lo_gap = Vec3::from_array(std::array::from_fn(|a| {
            if c0[a] - ring <= 0 {
                far
            } else {
                x[a] - lo[a]
            }
        }));
        let hi_gap = Vec3::from_array(std::array::from_fn(|a| {
            if c0[a] + ring >= res[a] - 1 {
                far
            } else {
                hi[a] - x[a]
            }
        }));
        let d_min = lo_gap.min(hi_gap).min_element();
        let covers = (0..3).all(|a| c0[a] - ring <= 0 && c0[a] + ring >= res[a] - 1);
        if covers || d_min >= max_radius || (accepted >= k && d_min >= 0.0 && r2 <= d_min * d_min) {
            let result = KnnResult {
                flux,
                radius2: r2,
                accepted,
            };
            return (result, examined);
        }
        ring += 1;
    }
}

/// Which CPU estimate the software reference uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SoftwareEstimate {
    /// Jensen's balanced kd-tree, exactly the k nearest (figure 7c).
    KdTree,
    /// The kNN-grid on the CPU with the GPU's acceptance rules.
    KnnGrid,
}

/// The paper's software column: the same eye paths (the GPU's first diffuse
/// hits and direct light) and the same photons, with the radiance estimate
/// computed on the CPU.
pub fn software_image(
    out: &crate::render::RenderOutput,
    scene: &crate::scene::Scene,
    estimate: SoftwareEstimate,
) -> Option<crate::render::Image> {
    match estimate {
        SoftwareEstimate::KdTree => kd_tree_image(out, scene),
        SoftwareEstimate::KnnGrid => {
            let map = CpuPhotonMap::from_gpu(out.map()?);
            let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
            Some(software_image_with(&out.state.direct, scene, &|x| {
                knn_grid(&map, x, k, max_r)
            }))
        }
    }
}
