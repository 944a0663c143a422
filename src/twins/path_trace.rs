//! An independent estimator for diffuse-only scenes: a CPU path tracer with
//! next-event estimation (Kajiya 1986; direct light sampled at every diffuse
//! vertex), box-filtered over jittered pixel samples. It shares no code with
//! the photon passes but the intersection twins, and nothing with SPPM, so
//! SPPM agreeing with it is evidence of truth, not of self-agreement.
//!
//! Each path: from the eye, emitters seen directly count once (a one-sided
//! light seen from its front); at each diffuse vertex every light is sampled
//! (one shadow ray to each point light, one uniform point on each area light),
//! then the path continues by a cosine-distributed direction, Russian roulette
//! with the largest albedo channel. Emitters hit after a bounce do not count:
//! next-event estimation already has. No depth limit.

use glam::{DVec3, Vec3};

use crate::sampling::sample_cosine;
use crate::scene::{triangle_area, Geometry, Light, Material, Scene};

use super::light::area_light_point;
use super::ray_trace::{closest_hit, eye_ray_at, offset_scale, point_light, toward_emitter};
use super::shading::facing_shading_normal;

/// A small, fast generator for the path tracer's own numbers (xorshift64*).
struct Rng(u64);

impl Rng {
    fn new(seed: u64) -> Self {
        Self(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1)
    }

    fn next(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        ((self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 40) as f32) / (1u64 << 24) as f32
    }
}

/// Per-pixel mean radiance and the variance of that mean, row 0 at the top.
pub struct PathTraced {
    pub width: u32,
    pub height: u32,
    pub mean: Vec<[f64; 3]>,
    pub variance_of_mean: Vec<[f64; 3]>,
}

/// Path traces `scene` (diffuse surfaces and emitters only) at `spp` jittered
/// samples per pixel, on two threads of rows.
pub fn path_trace(scene: &Scene, width: u32, height: u32, spp: u32, seed: u64) -> PathTraced {
    assert!(
        scene
            .materials
            .iter()
            .all(|m| matches!(m, Material::Diffuse { .. } | Material::Emitter { .. })),
        "the path tracer handles diffuse-only scenes"
    );
    let rows: Vec<u32> = (0..height).collect();
    let halves = rows.split_at(rows.len() / 2);
    let run = |rows: &[u32]| -> Vec<([f64; 3], [f64; 3])> {
        let mut out = Vec::new();
        for &y in rows {
            for x in 0..width {
                let mut rng = Rng::new(
                    seed ^ ((y as u64) << 32 | x as u64).wrapping_mul(0xD6E8_FEB8_6659_FD93),
                );
                let (mut s, mut s2) = (DVec3::ZERO, DVec3::ZERO);
                for _ in 0..spp {
                    let (o, d) = eye_ray_at(
                        scene,
                        width,
                        height,
                        x as f32 + rng.next(),
                        y as f32 + rng.next(),
                    );
                    let l = radiance(scene, o, d, &mut rng).as_dvec3();
                    s += l;
                    s2 += l * l;
                }
                let n = spp as f64;
                let mean = s / n;
                let var = ((s2 / n - mean * mean) * n / (n - 1.0).max(1.0)).max(DVec3::ZERO) / n;
                out.push((mean.to_array(), var.to_array()));
            }
        }
        out
    };
    let (a, b) = std::thread::scope(|s| {
        let a = s.spawn(|| run(halves.0));
        let b = run(halves.1);
        (a.join().expect("path tracer thread"), b)
    });
    let all: Vec<_> = a.into_iter().chain(b).collect();
    PathTraced {
        width,
        height,
        mean: all.iter().map(|p| p.0).collect(),
        variance_of_mean: all.iter().map(|p| p.1).collect(),
    }
}

/// One path's radiance along the eye ray (o, d).
fn radiance(scene: &Scene, mut o: Vec3, mut d: Vec3, rng: &mut Rng) -> Vec3 {
    let floor = 1e-6 * scene.size();
    let mut l = Vec3::ZERO;
    let mut beta = Vec3::ONE;
    for depth in 0.. {
        let Some((shape, _, p, n)) = closest_hit(scene, o, d) else {
            break;
        };
        let s = &scene.shapes[shape];
        match scene.materials[s.material] {
            Material::Emitter { radiance, normal } => {
                if depth == 0 && d.dot(normal.unwrap_or(n)) < 0.0 {
                    l += beta * radiance;
                }
                break;
            }
            Material::Diffuse { albedo } => {
                let nf = if n.dot(d) < 0.0 { n } else { -n };
                // With vertex normals the cosines are the shading normal's;
                // the geometric normal decides sides.
                let ms = s
                    .normals
                    .is_some()
                    .then(|| facing_shading_normal(s, p, n, d));
                let origin = p + offset_scale(p, floor) * nf;
                l += beta * albedo / std::f32::consts::PI
                    * direct(scene, origin, nf, ms, floor, rng);
                let keep = albedo.max_element();
                if keep <= 0.0 || rng.next() >= keep {
                    break;
                }
                beta *= albedo / keep;
                d = sample_cosine(nf, rng.next(), rng.next());
                // Sampled by the geometric cosine: weigh by cos_s / cos_g.
                if let Some(ms) = ms {
                    beta *= ms.dot(d).max(0.0) / nf.dot(d);
                }
                o = origin;
            }
            _ => unreachable!("diffuse-only scenes"),
        }
    }
    l
}

/// Irradiance at `origin` (normal `nf`, shading normal `ms` if any) from
/// every light, one sample each.
fn direct(
    scene: &Scene,
    origin: Vec3,
    nf: Vec3,
    ms: Option<Vec3>,
    floor: f32,
    rng: &mut Rng,
) -> Vec3 {
    let cosine = |wi: Vec3, c: f32| ms.map_or(c, |m| m.dot(wi).max(0.0));
    let mut e = Vec3::ZERO;
    for light in &scene.lights {
        // A point of an area light, its normal, and 1 / its pdf (the area).
        let (q, normal, radiance, area) = match *light {
            Light::Point {
                position,
                intensity,
            } => {
                e += point_light(scene, origin, nf, (position, intensity), cosine);
                continue;
            }
            Light::Area {
                normal, radiance, ..
            } => {
                let q = area_light_point(light, rng.next(), rng.next());
                (q, normal, radiance, light.area(&scene.shapes))
            }
            Light::Triangles { radiance, .. } => {
                let (q, normal) = triangle_light_point(scene, light, rng);
                (q, normal, radiance, light.area(&scene.shapes))
            }
        };
        if let Some((wi, c, cl, dist)) = toward_emitter(scene, origin, nf, (q, normal), floor) {
            e += radiance * cosine(wi, c) * cl / (dist * dist) * area;
        }
    }
    e
}

/// A point uniform over a `Triangles` light's area (a triangle by area, by a
/// linear scan, then a uniform point in it) and its triangle's normal.
fn triangle_light_point(scene: &Scene, light: &Light, rng: &mut Rng) -> (Vec3, Vec3) {
    let Light::Triangles { first, count, .. } = *light else {
        return (Vec3::ZERO, Vec3::Y);
    };
    let shapes = &scene.shapes[first..first + count];
    let mut pick = rng.next() * light.area(&scene.shapes);
    let mut chosen = shapes[shapes.len() - 1].geometry;
    for s in shapes {
        let a = triangle_area(&s.geometry);
        if pick < a {
            chosen = s.geometry;
            break;
        }
        pick -= a;
    }
    let Geometry::Triangle { v0, v1, v2 } = chosen else {
        return (Vec3::ZERO, Vec3::Y);
    };
    let (mut b1, mut b2) = (rng.next(), rng.next());
    if b1 + b2 > 1.0 {
        (b1, b2) = (1.0 - b1, 1.0 - b2);
    }
    (
        v0 + b1 * (v1 - v0) + b2 * (v2 - v0),
        (v1 - v0).cross(v2 - v0).normalize(),
    )
}
