//! Each GLSL intersection routine against its Rust twin on thousands of random
//! rays (grazing ones included), and no self-intersection at any scene scale.

use crate::common;

use crate::common::Rng;

use glam::{DVec3, Vec3};
use photonmap::gpu::Gpu;
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::{Geometry, Light, Material, Scene, Shape};
use photonmap::twins::intersect::{boundary_margin, intersect_geometry};

fn one_shape_scene(g: Geometry) -> Scene {
    let light_at = match g {
        Geometry::Sphere { center, .. } => center,
        Geometry::Cylinder { base, .. } => base,
        Geometry::Parallelogram { corner, .. } => corner,
        Geometry::Triangle { v0, .. } => v0,
    };
    Scene::with_shapes(
        vec![Shape::new(g, 0)],
        vec![Material::Diffuse {
            albedo: Vec3::splat(0.5),
        }],
        vec![Light::Point {
            position: light_at,
            intensity: Vec3::ONE,
        }],
    )
}

/// Runs glsl/test/intersect_twin.frag over rays; returns (t, u, v, hit) per ray.
fn gpu_hits(
    gpu: &Gpu,
    scene: &Scene,
    origins: &[Vec3],
    dirs: &[Vec3],
    normals: Option<&[Vec3]>,
) -> Vec<[f32; 4]> {
    let textures = SceneTextures::new(gpu, scene).unwrap();
    let texels = |v: &[Vec3]| -> Vec<[f32; 4]> { v.iter().map(|&p| common::texel(p)).collect() };
    let (o, d, n) = (
        texels(origins),
        texels(dirs),
        texels(normals.unwrap_or(dirs)),
    );
    common::intersect_twin(gpu, &textures, 128, [&o, &d, &n], normals.is_some() as i32)
}

/// A point on the primitive's surface or its boundary, for aiming rays.
fn surface_sample(g: &Geometry, rng: &mut Rng, boundary: bool) -> DVec3 {
    match *g {
        Geometry::Sphere { center, radius } => center.as_dvec3() + rng.unit() * radius as f64,
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            let a = axis.as_dvec3();
            let side = a.any_orthonormal_vector();
            let other = a.cross(side);
            let phi = rng.f64() * std::f64::consts::TAU;
            let h = if boundary {
                (rng.f64() < 0.5) as i32 as f64 * height as f64
            } else {
                rng.f64() * height as f64
            };
            base.as_dvec3() + a * h + (side * phi.cos() + other * phi.sin()) * radius as f64
        }
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => {
            let (mut u, mut v) = (rng.f64(), rng.f64());
            if boundary {
                if rng.f64() < 0.5 {
                    u = (u > 0.5) as i32 as f64
                } else {
                    v = (v > 0.5) as i32 as f64
                }
            }
            corner.as_dvec3() + u * edge1.as_dvec3() + v * edge2.as_dvec3()
        }
        Geometry::Triangle { v0, v1, v2 } => {
            let (mut u, mut v) = (rng.f64(), rng.f64());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            if boundary {
                match (rng.f64() * 3.0) as i32 {
                    0 => u = 0.0,
                    1 => v = 0.0,
                    _ => v = 1.0 - u,
                }
            }
            v0.as_dvec3() + u * (v1 - v0).as_dvec3() + v * (v2 - v0).as_dvec3()
        }
    }
}

fn shapes() -> Vec<(&'static str, Geometry)> {
    vec![
        (
            "sphere",
            Geometry::Sphere {
                center: Vec3::new(0.2, -0.1, 0.3),
                radius: 0.8,
            },
        ),
        (
            "cylinder",
            Geometry::Cylinder {
                base: Vec3::new(0.1, -0.3, 0.0),
                axis: Vec3::new(0.3, 1.0, 0.2).normalize(),
                radius: 0.7,
                height: 0.9,
            },
        ),
        (
            "parallelogram",
            Geometry::Parallelogram {
                corner: Vec3::new(-0.5, -0.2, -0.4),
                edge1: Vec3::new(1.2, 0.1, 0.0),
                edge2: Vec3::new(0.2, 0.3, 1.0),
            },
        ),
        (
            "triangle",
            Geometry::Triangle {
                v0: Vec3::new(-0.6, 0.0, -0.5),
                v1: Vec3::new(0.7, 0.2, -0.3),
                v2: Vec3::new(0.0, -0.1, 0.8),
            },
        ),
    ]
}

#[test]
fn glsl_intersections_match_their_rust_twins() {
    let gpu = common::gpu();
    for (name, g) in shapes() {
        let mut rng = Rng(0x1234_5678 ^ name.len() as u64);
        let (mut origins, mut dirs) = (Vec::new(), Vec::new());
        for i in 0..6000 {
            let o = rng.unit() * (1.5 + 3.0 * rng.f64());
            let d = match i % 3 {
                0 => (surface_sample(&g, &mut rng, false) - o).normalize(), // aimed at the surface
                1 => (surface_sample(&g, &mut rng, true) - o).normalize(),  // grazing the boundary
                _ => rng.unit(),
            };
            // Grazing along the surface itself: directions nearly tangent.
            let d = if i % 7 == 0 {
                (d + rng.unit() * 1e-3).normalize()
            } else {
                d
            };
            origins.push(o.as_vec3());
            dirs.push(d.as_vec3());
        }
        let scene = one_shape_scene(g);
        let gpu_out = gpu_hits(&gpu, &scene, &origins, &dirs, None);
        let (mut hits, mut disagree_near_boundary, mut bad) = (0, 0, Vec::new());
        for k in 0..origins.len() {
            let cpu = intersect_geometry(&g, origins[k], dirs[k]);
            let gpu_hit = gpu_out[k];
            let margin = boundary_margin(&g, origins[k], dirs[k]);
            match (cpu, gpu_hit[3] > 0.0) {
                (Some((t, u, v)), true) => {
                    hits += 1;
                    let scale = 1.0f32.max(t);
                    let rel = (gpu_hit[0] - t).abs() / scale;
                    let uv_err = (gpu_hit[1] - u).abs().max((gpu_hit[2] - v).abs());
                    if (rel > 1e-4 || uv_err > 1e-4) && margin > 1e-3 {
                        bad.push(format!(
                            "ray {k}: t {t} vs {} (uv {u},{v} vs {},{}), margin {margin}",
                            gpu_hit[0], gpu_hit[1], gpu_hit[2]
                        ));
                    }
                }
                (None, false) => {}
                (c, _) => {
                    // Only where f32 rounding can decide (~100 ulp of the boundary).
                    if margin > 1e-5 {
                        bad.push(format!(
                            "ray {k}: cpu {c:?} gpu {gpu_hit:?} margin {margin}"
                        ));
                    } else {
                        disagree_near_boundary += 1;
                    }
                }
            }
        }
        eprintln!("{name}: {hits} hits agree, {disagree_near_boundary} disagreements within 1e-5 of the boundary");
        assert!(
            hits > 1500,
            "{name}: too few hits ({hits}) to test anything"
        );
        assert!(
            bad.is_empty(),
            "{name}: {} rays disagree away from the boundary:\n{}",
            bad.len(),
            bad[..bad.len().min(10)].join("\n")
        );
    }
}

/// Rays leaving a surface point (moved off by offset_origin) never hit the
/// surface they leave, at scales 1e-3 .. 1e3 and positions up to 1e4 away.
#[test]
fn no_self_intersection_at_any_scale() {
    let gpu = common::gpu();
    for scale in [1e-3f64, 1.0, 1e3] {
        for shift in [0.0f64, 1e2, 1e4] {
            let shift = DVec3::new(shift, -0.5 * shift, 0.25 * shift);
            if shift.length() > 0.0 && shift.length() / scale > 1e5 {
                continue; // a scene 1e-3 across at 1e4 from the origin: below float resolution
            }
            for (name, g0) in shapes() {
                let t = |p: Vec3| (p.as_dvec3() * scale + shift).as_vec3();
                let s = scale as f32;
                let g = g0.scaled(s, t);
                let mut rng = Rng(0xfeed ^ name.len() as u64);
                let (mut pts, mut normals, mut dirs, mut legit) = (vec![], vec![], vec![], vec![]);
                for _ in 0..3000 {
                    let p = surface_sample(&g, &mut rng, false);
                    let n = match g {
                        Geometry::Sphere { center, .. } => (p - center.as_dvec3()).normalize(),
                        Geometry::Cylinder { base, axis, .. } => {
                            let r = p - base.as_dvec3();
                            (r - r.dot(axis.as_dvec3()) * axis.as_dvec3()).normalize()
                        }
                        Geometry::Parallelogram { edge1, edge2, .. } => {
                            edge1.as_dvec3().cross(edge2.as_dvec3()).normalize()
                        }
                        Geometry::Triangle { v0, v1, v2 } => {
                            (v1 - v0).as_dvec3().cross((v2 - v0).as_dvec3()).normalize()
                        }
                    };
                    // Directions at least ~0.6 degrees off the tangent plane, either side.
                    let mut d = rng.unit();
                    if d.dot(n).abs() < 0.01 {
                        d = (d + n * 0.05 * d.dot(n).signum()).normalize();
                    }
                    // The legitimate hit of a ray going into a closed sphere: the far side.
                    let far = match g {
                        Geometry::Sphere { radius, .. } if d.dot(n) < 0.0 => {
                            Some(-2.0 * radius as f64 * d.dot(n))
                        }
                        _ => None,
                    };
                    pts.push(p.as_vec3());
                    normals.push(n.as_vec3());
                    dirs.push(d.as_vec3());
                    legit.push(far);
                }
                let scene = one_shape_scene(g);
                let out = gpu_hits(&gpu, &scene, &pts, &dirs, Some(&normals));
                let size = scale * 0.7;
                let mut self_hits = 0;
                for k in 0..pts.len() {
                    if out[k][3] == 0.0 {
                        continue;
                    }
                    let t_hit = out[k][0] as f64;
                    let ok = match (legit[k], g) {
                        // The far side (its distance moves a little with the offset origin).
                        (Some(far), _) => t_hit > 0.5 * far,
                        // Cylinder: going inward can meet the far wall, never the near one.
                        (None, Geometry::Cylinder { .. }) => t_hit > 1e-2 * size,
                        (None, _) => false,
                    };
                    if !ok {
                        if self_hits < 3 {
                            eprintln!(
                                "{name}: t {t_hit} expected {:?}, d.n {}",
                                legit[k],
                                dirs[k].dot(normals[k])
                            );
                        }
                        self_hits += 1;
                    }
                }
                assert_eq!(
                    self_hits, 0,
                    "{name} at scale {scale}, shifted {shift:?}: {self_hits} self-intersections"
                );
            }
        }
    }
}
