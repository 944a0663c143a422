//! Jensen's projection maps (Jensen, "Global Illumination Using Photon Maps",
//! 1996): when a scene stores caustics only, a photon that leaves its light
//! towards no specular object is wasted. Each light's emission is split into
//! resolution² cells of equal emitted power: cells of the unit square of the two
//! uniforms that emission maps to a direction (uniform sphere for point lights,
//! cosine hemisphere for area lights; both maps preserve measure). A cell is
//! kept when some direction in it, from some point of the light, can reach the
//! bounding sphere of a specular shape. Photons leave through kept cells only,
//! uniformly among them, and carry the light's power times the kept fraction,
//! so the expected flux of every caustic is unchanged.

use glam::{Vec3, Vec4};

use crate::sampling::{basis_around, sample_cosine, sample_sphere};
use crate::scene::{Geometry, Light, Scene};

/// Cells per side: the scene format's default and limits, defined with the
/// format's others in `scene::defaults` (128² cells, 4 a texel, fit a
/// 4,097-texel row on any GL 4.5 driver).
pub use crate::scene::defaults::{
    DEFAULT_PROJECTION_RESOLUTION as DEFAULT_RESOLUTION,
    MAX_PROJECTION_RESOLUTION as MAX_RESOLUTION, MIN_PROJECTION_RESOLUTION as MIN_RESOLUTION,
};

/// Directions sampled per cell side to bound a cell's cone.
const CELL_SAMPLES: usize = 9;
/// Above this many bounding spheres (meshes), they are merged per cell of a
/// coarse grid, so the map's cost does not grow with triangles.
const MAX_SPHERES: usize = 256;
/// Pieces a cylinder (around its axis) or a parallelogram (along its longer
/// edge, and its shorter in proportion) is bounded in: one sphere around a
/// whole ring or a long strip would keep far more directions than reach it.
const PIECES: usize = 16;
const MERGE_GRID: usize = 4;
/// Angle added to every test, radians: f32 rounding of directions.
const ANGLE_MARGIN: f32 = 1e-3;

/// One light's kept cells.
#[derive(Clone, Debug, PartialEq)]
pub struct ProjectionMap {
    pub resolution: u32,
    /// Kept cells, index = row * resolution + column, where the column is the
    /// first uniform of the light's direction and the row the second.
    pub cells: Vec<u32>,
}

impl ProjectionMap {
    /// The share of the light's power (and of its directions' measure) kept.
    pub fn fraction(&self) -> f64 {
        self.cells.len() as f64 / (self.resolution as f64 * self.resolution as f64)
    }

    /// The cell that uniforms (u, v) in [0, 1) fall in.
    pub fn cell_of(&self, u: f32, v: f32) -> u32 {
        let n = self.resolution;
        let c = ((u * n as f32) as u32).min(n - 1);
        let r = ((v * n as f32) as u32).min(n - 1);
        r * n + c
    }

    pub fn keeps(&self, u: f32, v: f32) -> bool {
        self.cells.binary_search(&self.cell_of(u, v)).is_ok()
    }
}

/// Every light's projection map.
#[derive(Clone, Debug, PartialEq)]
pub struct ProjectionMaps {
    pub resolution: u32,
    pub maps: Vec<ProjectionMap>,
}

/// The projection texture (one row a light): texel 0 holds (cdf, probability,
/// kept fraction, kept cells); then the kept cell indices, four a texel.
#[derive(Clone, Debug)]
pub struct ProjectionTexels {
    pub width: u32,
    pub height: u32,
    pub data: Vec<f32>,
}

impl ProjectionTexels {
    pub fn texel(&self, light: usize, i: usize) -> Vec4 {
        let at = (light * self.width as usize + i) * 4;
        Vec4::from_slice(&self.data[at..at + 4])
    }
}

impl ProjectionMaps {
    pub fn for_scene(scene: &Scene) -> Self {
        let resolution = scene.photon_map.projection_resolution;
        let spheres = specular_spheres(scene);
        let maps = scene
            .lights
            .iter()
            .map(|light| light_map(light, resolution, &spheres))
            .collect();
        Self { resolution, maps }
    }

    /// Power of each light that leaves through kept cells (sum of channels):
    /// what photon emission picks lights by.
    pub fn kept_power(&self, scene: &Scene) -> Vec<f64> {
        scene
            .lights
            .iter()
            .zip(&self.maps)
            .map(|(l, m)| l.power(&scene.shapes).element_sum() as f64 * m.fraction())
            .collect()
    }

    /// The share of all the lights' power that leaves through kept cells.
    pub fn kept_power_fraction(&self, scene: &Scene) -> f64 {
        let total: f64 = scene
            .lights
            .iter()
            .map(|l| l.power(&scene.shapes).element_sum() as f64)
            .sum();
        self.kept_power(scene).iter().sum::<f64>() / total.max(f64::MIN_POSITIVE)
    }

    pub fn texels(&self, scene: &Scene) -> ProjectionTexels {
        let longest = self.maps.iter().map(|m| m.cells.len()).max().unwrap_or(0);
        let width = 1 + longest.div_ceil(4) as u32;
        let height = self.maps.len() as u32;
        let mut data = vec![0f32; (width * height * 4) as usize];
        let kept = self.kept_power(scene);
        let total: f64 = kept.iter().sum();
        let last_used = kept.iter().rposition(|&w| w > 0.0);
        let mut cdf = 0.0f64;
        for (l, map) in self.maps.iter().enumerate() {
            let probability = if total > 0.0 { kept[l] / total } else { 0.0 };
            cdf += probability;
            // Lights from the last one used on close the CDF exactly, so a
            // pick just below 1 never lands on a light with nothing kept.
            let cdf_here = if last_used.is_some_and(|u| l >= u) {
                1.0
            } else {
                cdf
            };
            let row = l * width as usize * 4;
            data[row..row + 4].copy_from_slice(&[
                cdf_here as f32,
                probability as f32,
                map.fraction() as f32,
                map.cells.len() as f32,
            ]);
            for (i, &c) in map.cells.iter().enumerate() {
                data[row + 4 + i] = c as f32;
            }
        }
        ProjectionTexels {
            width,
            height,
            data,
        }
    }
}

/// The direction a light emits for the uniforms (u, v) of its direction: the
/// mapping of glsl/photon/emit.frag.
pub fn emission_direction(light: &Light, u: f32, v: f32) -> Vec3 {
    match *light {
        Light::Point { .. } => sample_sphere(u, v),
        Light::Area { normal, .. } => sample_cosine(normal, u, v),
        // Each triangle's own normal: no one direction (the map keeps all).
        Light::Triangles { .. } => sample_cosine(Vec3::Y, u, v),
    }
}

/// A sphere holding the whole shape.
pub fn bounding_sphere(g: &Geometry) -> (Vec3, f32) {
    match *g {
        Geometry::Sphere { center, radius } => (center, radius),
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => (
            base + axis * (0.5 * height),
            (radius * radius + 0.25 * height * height).sqrt(),
        ),
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => (
            corner + 0.5 * (edge1 + edge2),
            0.5 * (edge1 + edge2).length().max((edge1 - edge2).length()),
        ),
        Geometry::Triangle { v0, v1, v2 } => {
            let c = (v0 + v1 + v2) / 3.0;
            let r = (v0 - c)
                .length()
                .max((v1 - c).length())
                .max((v2 - c).length());
            (c, r)
        }
    }
}

/// Spheres holding the light's points: a point light's own, or an area
/// light's patches (the map keeps what any patch can reach, and a small patch
/// widens the cones to the specular shapes less than the whole light would).
fn light_spheres(light: &Light) -> Vec<(Vec3, f32)> {
    match *light {
        Light::Point { position, .. } => vec![(position, 0.0)],
        Light::Area {
            corner,
            edge1,
            edge2,
            ..
        } => bounding_spheres(&Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        }),
        Light::Triangles { .. } => Vec::new(),
    }
}

/// Spheres that together hold the whole shape, tighter than one: a cylinder
/// is cut into PIECES arcs, a parallelogram into near-square patches.
pub fn bounding_spheres(g: &Geometry) -> Vec<(Vec3, f32)> {
    match *g {
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            // Arc k spans angles [k, k+1] * step; its sphere sits on the
            // chord's midpoint at mid-height and reaches the arc's corners.
            let step = 2.0 * std::f32::consts::PI / PIECES as f32;
            let (t, b) = basis_around(axis);
            let half = 0.5 * step;
            let reach = ((radius * half.sin()).powi(2) + 0.25 * height * height).sqrt();
            (0..PIECES)
                .map(|k| {
                    let mid = (k as f32 + 0.5) * step;
                    let c = base
                        + axis * (0.5 * height)
                        + radius * half.cos() * (mid.cos() * t + mid.sin() * b);
                    (c, reach * 1.0001)
                })
                .collect()
        }
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => {
            let (l1, l2) = (edge1.length(), edge2.length());
            let longer = l1.max(l2).max(f32::MIN_POSITIVE);
            let n1 = ((PIECES as f32 * l1 / longer).ceil() as usize).max(1);
            let n2 = ((PIECES as f32 * l2 / longer).ceil() as usize).max(1);
            let (e1, e2) = (edge1 / n1 as f32, edge2 / n2 as f32);
            let mut out = Vec::with_capacity(n1 * n2);
            for i in 0..n1 {
                for j in 0..n2 {
                    let (c, r) = bounding_sphere(&Geometry::Parallelogram {
                        corner: corner + i as f32 * e1 + j as f32 * e2,
                        edge1: e1,
                        edge2: e2,
                    });
                    out.push((c, r * 1.0001));
                }
            }
            out
        }
        _ => vec![bounding_sphere(g)],
    }
}

/// Bounding spheres of the specular shapes; many (meshes) are merged per cell
/// of a coarse grid over their centres.
pub fn specular_spheres(scene: &Scene) -> Vec<(Vec3, f32)> {
    let spheres: Vec<(Vec3, f32)> = scene
        .shapes
        .iter()
        .filter(|s| scene.materials[s.material].is_specular())
        .flat_map(|s| bounding_spheres(&s.geometry))
        .collect();
    if spheres.len() <= MAX_SPHERES {
        return spheres;
    }
    let (lo, hi) = spheres.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), (c, _)| (lo.min(*c), hi.max(*c)),
    );
    let n = MERGE_GRID;
    let cell = |c: Vec3| {
        let t = ((c - lo) / (hi - lo).max(Vec3::splat(f32::MIN_POSITIVE))) * n as f32;
        let i = |x: f32| (x as usize).min(n - 1);
        i(t.x) + n * (i(t.y) + n * i(t.z))
    };
    // Per grid cell, the box of its spheres; then the sphere around that box.
    let mut boxes = vec![None::<(Vec3, Vec3)>; n * n * n];
    for &(c, r) in &spheres {
        let b = &mut boxes[cell(c)];
        let (l, h) = (c - Vec3::splat(r), c + Vec3::splat(r));
        *b = Some(match *b {
            None => (l, h),
            Some((bl, bh)) => (bl.min(l), bh.max(h)),
        });
    }
    boxes
        .into_iter()
        .flatten()
        .map(|(l, h)| (0.5 * (l + h), 0.5 * (h - l).length()))
        .collect()
}

/// The angle between two vectors, accurate near 0 (unlike acos of a dot).
fn angle(a: Vec3, b: Vec3) -> f32 {
    a.cross(b).length().atan2(a.dot(b))
}

/// A cone holding every direction of cell (column, row): its axis, and a
/// half-angle that is the largest sampled angle plus the largest gap between
/// neighbouring samples (no direction of the cell is further than that from
/// the nearest sample).
fn cell_cone(light: &Light, resolution: u32, column: u32, row: u32) -> (Vec3, f32) {
    let n = CELL_SAMPLES;
    let step = 1.0 / (resolution as f32 * (n - 1) as f32);
    let (u0, v0) = (
        column as f32 / resolution as f32,
        row as f32 / resolution as f32,
    );
    let mut dirs = [[Vec3::ZERO; CELL_SAMPLES]; CELL_SAMPLES];
    let mut sum = Vec3::ZERO;
    for (j, line) in dirs.iter_mut().enumerate() {
        for (i, d) in line.iter_mut().enumerate() {
            // The upper edges just inside [0, 1), as the uniforms are.
            let u = (u0 + i as f32 * step).min(1.0 - f32::EPSILON);
            let v = (v0 + j as f32 * step).min(1.0 - f32::EPSILON);
            *d = emission_direction(light, u, v);
            sum += *d;
        }
    }
    let axis = if sum.length() > 1e-6 {
        sum.normalize()
    } else {
        dirs[n / 2][n / 2]
    };
    let mut widest = 0f32;
    let mut gap = 0f32;
    for j in 0..n {
        for i in 0..n {
            widest = widest.max(angle(axis, dirs[j][i]));
            if i + 1 < n {
                gap = gap.max(angle(dirs[j][i], dirs[j][i + 1]));
            }
            if j + 1 < n {
                gap = gap.max(angle(dirs[j][i], dirs[j + 1][i]));
            }
        }
    }
    (axis, widest + gap)
}

fn light_map(light: &Light, resolution: u32, spheres: &[(Vec3, f32)]) -> ProjectionMap {
    // The emissive triangles of an OBJ group emit about each triangle's own
    // normal, so a cell of the direction's uniforms is no one cone: their
    // map keeps every cell (photons are not aimed; nothing is lost).
    if let Light::Triangles { .. } = light {
        let cells = (0..resolution * resolution).collect();
        return ProjectionMap { resolution, cells };
    }
    // A ray from a point p of a light patch that meets sphere (c, r) passes
    // within r + patch radius of c when moved to the patch's centre: so the
    // cone from the centre to the grown sphere holds every useful direction.
    let patches = light_spheres(light);
    let cones: Vec<Option<(Vec3, f32)>> = patches
        .iter()
        .flat_map(|&patch| spheres.iter().map(move |&sphere| (patch, sphere)))
        .map(|((origin, light_radius), (c, r))| {
            let to = c - origin;
            let grown = r + light_radius;
            let dist = to.length();
            if dist <= grown * 1.0001 {
                None // the light is inside: every direction may reach it
            } else {
                Some((to / dist, (grown / dist).asin()))
            }
        })
        .collect();
    let everything = cones.iter().any(Option::is_none);
    let mut cells = Vec::new();
    for row in 0..resolution {
        for column in 0..resolution {
            let keep = everything || {
                let (axis, half) = cell_cone(light, resolution, column, row);
                cones
                    .iter()
                    .flatten()
                    .any(|&(to, alpha)| angle(axis, to) <= alpha + half + ANGLE_MARGIN)
            };
            if keep {
                cells.push(row * resolution + column);
            }
        }
    }
    ProjectionMap { resolution, cells }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Material, Shape};

    fn point_and_sphere(distance: f32, radius: f32) -> Scene {
        Scene::with_shapes(
            vec![Shape::new(
                Geometry::Sphere {
                    center: Vec3::new(0.0, 0.0, -distance),
                    radius,
                },
                0,
            )],
            vec![Material::Mirror {
                reflectance: Vec3::ONE,
            }],
            vec![Light::Point {
                position: Vec3::ZERO,
                intensity: Vec3::ONE,
            }],
        )
    }

    #[test]
    fn a_far_small_sphere_keeps_few_cells_and_a_surrounding_one_keeps_all() {
        let far = ProjectionMaps::for_scene(&point_and_sphere(10.0, 1.0));
        // The sphere's cone is (1 - cos asin 0.1) / 2 = 0.25% of the sphere of
        // directions; the kept cells must hold it, rounded up to whole cells.
        let f = far.maps[0].fraction();
        assert!((0.0025..0.05).contains(&f), "kept fraction {f}");
        let inside = ProjectionMaps::for_scene(&point_and_sphere(0.5, 1.0));
        assert_eq!(inside.maps[0].fraction(), 1.0);
    }

    /// The pieces' spheres hold every point of the shape.
    #[test]
    fn pieces_hold_their_shape() {
        let shapes = [
            Geometry::Cylinder {
                base: Vec3::new(0.3, -1.0, 2.0),
                axis: Vec3::new(1.0, 2.0, 0.5).normalize(),
                radius: 1.5,
                height: 0.4,
            },
            Geometry::Parallelogram {
                corner: Vec3::new(-3.0, 0.0, 1.0),
                edge1: Vec3::new(6.0, 0.0, 0.0),
                edge2: Vec3::new(0.0, 0.3, 0.2),
            },
        ];
        for g in shapes {
            let spheres = bounding_spheres(&g);
            assert!(spheres.len() > 1);
            for i in 0..=64 {
                for j in 0..=64 {
                    let (a, b) = (i as f32 / 64.0, j as f32 / 64.0);
                    let p = match g {
                        Geometry::Cylinder {
                            base,
                            axis,
                            radius,
                            height,
                        } => {
                            let (t, bb) = basis_around(axis);
                            let phi = a * 2.0 * std::f32::consts::PI;
                            base + b * height * axis + radius * (phi.cos() * t + phi.sin() * bb)
                        }
                        Geometry::Parallelogram {
                            corner,
                            edge1,
                            edge2,
                        } => corner + a * edge1 + b * edge2,
                        _ => unreachable!(),
                    };
                    assert!(
                        spheres.iter().any(|&(c, r)| (p - c).length() <= r),
                        "{p} outside every piece of {g:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn texels_hold_the_cdf_and_every_kept_cell() {
        let scene = point_and_sphere(10.0, 1.0);
        let maps = ProjectionMaps::for_scene(&scene);
        let t = maps.texels(&scene);
        let head = t.texel(0, 0);
        assert_eq!((head.x, head.y), (1.0, 1.0));
        assert_eq!(head.w as usize, maps.maps[0].cells.len());
        for (i, &c) in maps.maps[0].cells.iter().enumerate() {
            assert_eq!(t.texel(0, 1 + i / 4)[i % 4], c as f32);
        }
    }
}
