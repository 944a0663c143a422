//! Vertex connection and merging's MIS weights (Georgiev, Křivánek,
//! Davidovič and Slusallek 2012, with the recurrences of their SmallVCM):
//! the partial sums dVCM, dVC and dVM that each subpath carries from vertex
//! to vertex, and each technique's balance-heuristic weight from them. These
//! are the twins of `glsl/vcm/mis.glsl`. For testing, `explicit_weights`
//! computes the same weights from every technique's full path pdf, which the
//! recurrences must reproduce and which sum to 1.
//!
//! Conventions (SmallVCM's): a light subpath starts at the light (vertex 0);
//! the camera subpath at the camera. Pdfs are per unit solid angle (`_w`) or
//! area (`_a`); Russian roulette's continuation probability is folded into
//! each BSDF pdf. `light_paths` is the number of light subpaths an iteration
//! traces (N), `eta_vcm` = π r² N; the merging and connection factors are
//! `eta_vcm` and its inverse (0 when that technique is off).

use glam::Vec3;

/// The partial sums a subpath carries (SmallVCM's dVCM, dVC, dVM).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Partials {
    pub d_vcm: f64,
    pub d_vc: f64,
    pub d_vm: f64,
}

/// Which techniques an iteration runs, as factors: `vm` = π r² N when
/// merging runs (else 0), `vc` = 1 / (π r² N) when connections run (else 0).
#[derive(Clone, Copy, Debug)]
pub struct Factors {
    pub vm: f64,
    pub vc: f64,
    pub light_paths: f64,
}

impl Factors {
    pub fn vcm(radius: f64, light_paths: f64) -> Self {
        let eta = std::f64::consts::PI * radius * radius * light_paths;
        Self {
            vm: eta,
            vc: 1.0 / eta,
            light_paths,
        }
    }
}

/// A light subpath's partials at its start: `direct_pdf_a` the pdf of
/// choosing the light point (light pick x 1 / area; 1 x pick for a point
/// light), `emission_pdf_w` that times the direction's pdf, `cos_light` the
/// cosine at the light (ignored for a point light, `delta`).
pub fn light_start(
    direct_pdf_a: f64,
    emission_pdf_w: f64,
    cos_light: f64,
    delta: bool,
    f: Factors,
) -> Partials {
    let d_vc = if delta {
        0.0
    } else {
        cos_light / emission_pdf_w
    };
    Partials {
        d_vcm: direct_pdf_a / emission_pdf_w,
        d_vc,
        d_vm: d_vc * f.vc,
    }
}

/// A camera subpath's partials at its start: `camera_pdf_w` the solid-angle
/// pdf of the eye ray's direction (image plane distance² / cos³).
pub fn camera_start(camera_pdf_w: f64, f: Factors) -> Partials {
    Partials {
        d_vcm: f.light_paths / camera_pdf_w,
        d_vc: 0.0,
        d_vm: 0.0,
    }
}

/// On arriving at a vertex at `distance` with `cos_in` to its normal (only
/// the first hit from a light at infinity keeps its `d_vcm`:
/// `scale_distance` false).
pub fn arrive(p: Partials, distance: f64, cos_in: f64, scale_distance: bool) -> Partials {
    let d_vcm = if scale_distance {
        p.d_vcm * distance * distance
    } else {
        p.d_vcm
    };
    Partials {
        d_vcm: d_vcm / cos_in,
        d_vc: p.d_vc / cos_in,
        d_vm: p.d_vm / cos_in,
    }
}

/// On leaving a non-delta vertex by a sampled direction: `cos_out` at the
/// vertex, `dir_pdf_w` the pdf of the direction taken and `rev_pdf_w` of the
/// reverse (both times the continuation probability).
pub fn scatter(p: Partials, cos_out: f64, dir_pdf_w: f64, rev_pdf_w: f64, f: Factors) -> Partials {
    Partials {
        d_vc: cos_out / dir_pdf_w * (p.d_vc * rev_pdf_w + p.d_vcm + f.vm),
        d_vm: cos_out / dir_pdf_w * (p.d_vm * rev_pdf_w + p.d_vcm * f.vc + 1.0),
        d_vcm: 1.0 / dir_pdf_w,
    }
}

/// On leaving a delta vertex (mirror, glass): the pdfs cancel.
pub fn scatter_specular(p: Partials, cos_out: f64) -> Partials {
    Partials {
        d_vcm: 0.0,
        d_vc: p.d_vc * cos_out,
        d_vm: p.d_vm * cos_out,
    }
}

/// The weight of a camera path that hits an area light, from the light's
/// `direct_pdf_a` (pick / area) and `emission_pdf_w` (that x cos / π) for
/// the point and direction hit; `camera` the partials on arrival.
pub fn emission_weight(camera: Partials, direct_pdf_a: f64, emission_pdf_w: f64) -> f64 {
    1.0 / (1.0 + direct_pdf_a * camera.d_vcm + emission_pdf_w * camera.d_vc)
}

/// The weight of next-event estimation at a camera vertex: the light sample's
/// `direct_pdf_w` (pick x solid angle at the vertex), `emission_pdf_w` (pick x
/// area x direction pdfs), the cosines at the light and at the vertex, and the
/// vertex's BSDF pdfs toward the light (`bsdf_dir_pdf_w`, 0 for a point light)
/// and back (`bsdf_rev_pdf_w`).
pub fn light_sample_weight(
    camera: Partials,
    direct_pdf_w: f64,
    emission_pdf_w: f64,
    (cos_light, cos_vertex): (f64, f64),
    (bsdf_dir_pdf_w, bsdf_rev_pdf_w): (f64, f64),
    f: Factors,
) -> f64 {
    let w_light = bsdf_dir_pdf_w / direct_pdf_w;
    let w_camera = emission_pdf_w * cos_vertex / (direct_pdf_w * cos_light)
        * (f.vm + camera.d_vcm + camera.d_vc * bsdf_rev_pdf_w);
    1.0 / (w_light + 1.0 + w_camera)
}

/// The weight of connecting a light vertex to the camera (light tracing):
/// `camera_pdf_a` the area pdf with which the camera would sample the light
/// vertex (image plane distance² / cos³ x cos at the vertex / distance²), and
/// the light vertex's reverse BSDF pdf (toward where it came from).
pub fn camera_connection_weight(
    light: Partials,
    camera_pdf_a: f64,
    bsdf_rev_pdf_w: f64,
    f: Factors,
) -> f64 {
    let w_light = camera_pdf_a / f.light_paths * (f.vm + light.d_vcm + light.d_vc * bsdf_rev_pdf_w);
    1.0 / (w_light + 1.0)
}

/// The weight of connecting a camera vertex to a light vertex: for each end,
/// the area pdf with which the other end's BSDF would sample it
/// (`*_dir_pdf_a`) and its own reverse solid-angle pdf.
pub fn vertex_connection_weight(
    camera: Partials,
    light: Partials,
    (camera_dir_pdf_a, camera_rev_pdf_w): (f64, f64),
    (light_dir_pdf_a, light_rev_pdf_w): (f64, f64),
    f: Factors,
) -> f64 {
    let w_light = camera_dir_pdf_a * (f.vm + light.d_vcm + light.d_vc * light_rev_pdf_w);
    let w_camera = light_dir_pdf_a * (f.vm + camera.d_vcm + camera.d_vc * camera_rev_pdf_w);
    1.0 / (w_light + 1.0 + w_camera)
}

/// The weight of merging a camera vertex with a light vertex at the same
/// place: the camera BSDF's pdfs toward the light vertex's incoming
/// direction (`camera_dir_pdf_w`, sampling it) and back (`camera_rev_pdf_w`).
pub fn merge_weight(
    camera: Partials,
    light: Partials,
    camera_dir_pdf_w: f64,
    camera_rev_pdf_w: f64,
    f: Factors,
) -> f64 {
    let w_light = light.d_vcm * f.vc + light.d_vm * camera_dir_pdf_w;
    let w_camera = camera.d_vcm * f.vc + camera.d_vm * camera_rev_pdf_w;
    1.0 / (w_light + 1.0 + w_camera)
}

/// A full path for the explicit weights: `points[0]` on an area light (its
/// normal `normals[0]`), diffuse surface vertices, and `points[k]` the
/// camera. A light subpath goes on from diffuse vertex i with probability
/// `continuation[i]`, a camera subpath with `camera_continuation[i]` (the
/// renderer's camera paths take a fraction of the light paths'); both
/// sample cosine-distributed directions.
pub struct Path {
    pub points: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub continuation: Vec<f64>,
    pub camera_continuation: Vec<f64>,
    /// The light's pick probability over its area.
    pub light_direct_pdf_a: f64,
    /// The camera's forward axis and image plane distance (in pixels).
    pub camera_forward: Vec3,
    pub image_plane_distance: f64,
}

/// A technique that can make a path: connection with `s` light vertices and
/// `t` camera vertices (s + t = vertices), or merging at vertex `i`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    Connect { s: usize, t: usize },
    Merge { i: usize },
}

fn cosine(path: &Path, i: usize, toward: usize) -> f64 {
    let d = (path.points[toward] - path.points[i]).normalize();
    f64::from(path.normals[i].dot(d).abs())
}

fn distance2(path: &Path, a: usize, b: usize) -> f64 {
    f64::from((path.points[a] - path.points[b]).length_squared())
}

/// The solid-angle pdf with which vertex `from` samples the direction to
/// `to`: the light's cosine emission (its pick and area pdf belong to vertex
/// 0), the camera's pixel sample, or a diffuse vertex's cosine lobe times the
/// continuation probability of the subpath that samples it: the light
/// subpath's toward the camera (`to` > `from`), the camera subpath's back.
fn direction_pdf(path: &Path, from: usize, to: usize) -> f64 {
    let k = path.points.len() - 1;
    if from == 0 {
        cosine(path, 0, to) / std::f64::consts::PI
    } else if from == k {
        let d = (path.points[to] - path.points[k]).normalize();
        let cos = f64::from(path.camera_forward.dot(d));
        path.image_plane_distance.powi(2) / cos.powi(3)
    } else {
        let continuation = if to > from {
            path.continuation[from]
        } else {
            path.camera_continuation[from]
        };
        continuation * cosine(path, from, to) / std::f64::consts::PI
    }
}

/// The area pdf of vertex `to` sampled from `from`.
fn area_pdf(path: &Path, from: usize, to: usize) -> f64 {
    direction_pdf(path, from, to) * cosine(path, to, from) / distance2(path, from, to)
}

/// Every technique's path pdf (the camera's pixel sample and N light paths
/// folded in as SmallVCM folds them: light tracing counts N times, merging
/// π r² N times), for the path's k + 1 vertices. Connections (next-event
/// estimation, hitting the light and light tracing among them) run when
/// `f.vc` > 0, merging when `f.vm` > 0.
pub fn technique_pdfs(path: &Path, f: Factors) -> Vec<(Technique, f64)> {
    let k = path.points.len() - 1;
    // light[j]: the pdf of vertices 0..=j sampled from the light.
    let mut light = vec![path.light_direct_pdf_a];
    for j in 1..k {
        light.push(light[j - 1] * area_pdf(path, j - 1, j));
    }
    // camera[j]: the pdf of vertices k - 1 down to j sampled from the camera.
    let mut camera = vec![1.0; k + 1];
    for j in (0..k).rev() {
        camera[j] = camera[j + 1] * area_pdf(path, j + 1, j);
    }
    let mut out = Vec::new();
    if f.vc > 0.0 {
        // s light vertices (0..s), t = k + 1 - s camera vertices (s..=k); the
        // camera is never hit, so light tracing needs s >= 2.
        for s in 0..k {
            let p_light = if s == 0 { 1.0 } else { light[s - 1] };
            out.push((Technique::Connect { s, t: k + 1 - s }, p_light * camera[s]));
        }
        out.push((
            Technique::Connect { s: k, t: 1 },
            light[k - 1] * f.light_paths,
        ));
    }
    if f.vm > 0.0 {
        for i in 1..k {
            out.push((Technique::Merge { i }, light[i] * camera[i] * f.vm));
        }
    }
    out
}

/// Each technique's balance-heuristic weight for the path.
pub fn explicit_weights(path: &Path, f: Factors) -> Vec<(Technique, f64)> {
    let pdfs = technique_pdfs(path, f);
    let sum: f64 = pdfs.iter().map(|(_, p)| p).sum();
    pdfs.into_iter().map(|(t, p)| (t, p / sum)).collect()
}

/// Each technique's weight as the renderer computes it: the partials carried
/// along the light subpath (vertex 0 up) and the camera subpath (vertex k
/// down), then the technique's weight function where the two meet.
pub fn recursive_weights(path: &Path, f: Factors) -> Vec<(Technique, f64)> {
    let k = path.points.len() - 1;
    let pi = std::f64::consts::PI;
    let d = |a: usize, b: usize| distance2(path, a, b).sqrt();
    // light_at[j]: the light subpath's partials on arriving at vertex j.
    let emission_pdf_w = path.light_direct_pdf_a * cosine(path, 0, 1) / pi;
    let mut partials = light_start(
        path.light_direct_pdf_a,
        emission_pdf_w,
        cosine(path, 0, 1),
        false,
        f,
    );
    let mut light_at = vec![partials];
    for j in 1..k {
        partials = arrive(partials, d(j - 1, j), cosine(path, j, j - 1), true);
        light_at.push(partials);
        if j + 1 < k {
            let (dir, rev) = (direction_pdf(path, j, j + 1), direction_pdf(path, j, j - 1));
            partials = scatter(partials, cosine(path, j, j + 1), dir, rev, f);
        }
    }
    // camera_at[j]: the camera subpath's partials on arriving at vertex j.
    let mut camera_at = vec![camera_start(0.0, f); k + 1];
    let mut partials = camera_start(direction_pdf(path, k, k - 1), f);
    for j in (0..k).rev() {
        partials = arrive(partials, d(j + 1, j), cosine(path, j, j + 1), true);
        camera_at[j] = partials;
        if j >= 1 {
            let (dir, rev) = (direction_pdf(path, j, j - 1), direction_pdf(path, j, j + 1));
            partials = scatter(partials, cosine(path, j, j - 1), dir, rev, f);
        }
    }
    let mut out = Vec::new();
    if f.vc > 0.0 {
        // Hitting the light.
        out.push((
            Technique::Connect { s: 0, t: k + 1 },
            emission_weight(
                camera_at[0],
                path.light_direct_pdf_a,
                emission_pdf_w_toward(path, 1),
            ),
        ));
        // Next-event estimation at vertex 1.
        let direct_pdf_w = path.light_direct_pdf_a * distance2(path, 0, 1) / cosine(path, 0, 1);
        out.push((
            Technique::Connect { s: 1, t: k },
            light_sample_weight(
                camera_at[1],
                direct_pdf_w,
                emission_pdf_w_toward(path, 1),
                (cosine(path, 0, 1), cosine(path, 1, 0)),
                (direction_pdf(path, 1, 0), direction_pdf(path, 1, 2)),
                f,
            ),
        ));
        // Connections between light vertex s - 1 and camera vertex s.
        for s in 2..k {
            let (l, c) = (s - 1, s);
            out.push((
                Technique::Connect { s, t: k + 1 - s },
                vertex_connection_weight(
                    camera_at[c],
                    light_at[l],
                    (area_pdf(path, c, l), direction_pdf(path, c, c + 1)),
                    (area_pdf(path, l, c), direction_pdf(path, l, l - 1)),
                    f,
                ),
            ));
        }
        // Light tracing: light vertex k - 1 to the camera.
        let camera_pdf_a = area_pdf(path, k, k - 1);
        out.push((
            Technique::Connect { s: k, t: 1 },
            camera_connection_weight(
                light_at[k - 1],
                camera_pdf_a,
                direction_pdf(path, k - 1, k - 2),
                f,
            ),
        ));
    }
    if f.vm > 0.0 {
        for i in 1..k {
            out.push((
                Technique::Merge { i },
                merge_weight(
                    camera_at[i],
                    light_at[i],
                    direction_pdf(path, i, i - 1),
                    direction_pdf(path, i, i + 1),
                    f,
                ),
            ));
        }
    }
    out
}

/// The light's emission pdf (pick x area x cosine lobe) of the direction
/// from vertex 0 toward vertex `to`.
fn emission_pdf_w_toward(path: &Path, to: usize) -> f64 {
    path.light_direct_pdf_a * cosine(path, 0, to) / std::f64::consts::PI
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small generator for random paths (xorshift64*).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f64 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
        }
        fn vec(&mut self, scale: f64) -> Vec3 {
            Vec3::new(
                ((self.next() - 0.5) * scale) as f32,
                ((self.next() - 0.5) * scale) as f32,
                ((self.next() - 0.5) * scale) as f32,
            )
        }
    }

    fn random_path(rng: &mut Rng, k: usize) -> Path {
        let points: Vec<Vec3> = (0..=k).map(|_| rng.vec(4.0)).collect();
        let normals = (0..=k).map(|_| rng.vec(2.0).normalize()).collect();
        let continuation: Vec<f64> = (0..=k).map(|_| 0.3 + 0.7 * rng.next()).collect();
        let fraction = 0.01 + 0.99 * rng.next();
        let camera_continuation = continuation.iter().map(|q| fraction * q).collect();
        // The camera looks roughly at its first vertex (cos well above 0).
        let toward = (points[k - 1] - points[k]).normalize();
        let camera_forward = (toward + 0.3 * rng.vec(1.0)).normalize();
        Path {
            points,
            normals,
            continuation,
            camera_continuation,
            light_direct_pdf_a: 0.05 + rng.next(),
            camera_forward,
            image_plane_distance: 100.0 + 500.0 * rng.next(),
        }
    }

    /// For random diffuse paths of 2 to 7 segments, camera subpaths going on
    /// with a random fraction of the light subpaths' probability, with every technique
    /// (VCM), connections only (BPT) and merging only (BPM): the weights the
    /// recurrences give equal the balance heuristic over every technique's
    /// full path pdf, and they sum to 1.
    #[test]
    fn recursive_weights_are_the_balance_heuristic_and_sum_to_one() {
        let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
        let mut checked = 0;
        for trial in 0..600 {
            let k = 2 + trial % 6;
            let path = random_path(&mut rng, k);
            let radius = 0.001 + 0.2 * rng.next();
            let light_paths = 1000.0 + 1e5 * rng.next();
            let vcm = Factors::vcm(radius, light_paths);
            let modes = [
                ("vcm", vcm),
                ("bpt", Factors { vm: 0.0, ..vcm }),
                ("bpm", Factors { vc: 0.0, ..vcm }),
            ];
            for (name, f) in modes {
                let explicit = explicit_weights(&path, f);
                let recursive = recursive_weights(&path, f);
                assert_eq!(explicit.len(), recursive.len(), "{name} k={k}");
                let sum: f64 = recursive.iter().map(|(_, w)| w).sum();
                assert!(
                    (sum - 1.0).abs() < 1e-9,
                    "{name} k={k}: the weights sum to {sum}"
                );
                for ((te, we), (tr, wr)) in explicit.iter().zip(&recursive) {
                    assert_eq!(te, tr);
                    assert!(
                        (we - wr).abs() <= 1e-9 * we.max(1e-300).max(*wr) + 1e-12,
                        "{name} k={k} {te:?}: explicit {we} recursive {wr}"
                    );
                }
                checked += recursive.len();
            }
        }
        assert!(checked > 5000, "{checked}");
    }
}
