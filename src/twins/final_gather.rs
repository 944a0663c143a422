//! Final gather on the CPU, the twin of glsl/render/gather_rays.frag and
//! gather_accumulate.frag: the same gather rays from the same random numbers,
//! traced by the CPU ray tracer, and the global map's estimate at their hits by
//! the CPU kNN-grid.

use glam::{Vec2, Vec3};

use crate::scene::{Material, Scene};

use super::bsdf::{rough_metal, sample as bsdf_sample, smooth_metal_factor, Frame};
use super::knn::{knn_grid, CpuPhotonMap};
use super::random::{rng_init, rng_next};
use super::ray_trace::{closest_hit, offset_scale};
use super::shading::{
    facing_shading_normal, radiance_refraction_scale, specular_about, specular_shaded,
};

/// Where a gather ray ends: the diffuse hit that queries the global map.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GatherHit {
    pub position: Vec3,
    /// Facing the gather ray.
    pub normal: Vec3,
    pub material: usize,
    /// Of the specular chain before the hit (1 without one).
    pub throughput: Vec3,
}

fn offset_origin(p: Vec3, n: Vec3, dir: Vec3, floor: f32) -> Vec3 {
    let s = offset_scale(p, floor);
    p + if dir.dot(n) >= 0.0 { s } else { -s } * n
}

/// Gather ray `ray` of pixel `px` from its first diffuse hit at `first` with
/// viewer-facing normal `n1`. With `fade` = IGI's bound m > 0, the bias
/// compensation's ray: only a diffuse hit straight from `first`, weighted by
/// 1 - f(d).
#[allow(clippy::too_many_arguments)]
pub fn gather_ray(
    scene: &Scene,
    first: Vec3,
    n1: Vec3,
    seed: u32,
    px: [u32; 2],
    ray: u32,
    max_depth: u32,
    fade: f32,
) -> Option<GatherHit> {
    let floor = 1e-6 * scene.size();
    let mut rng = rng_init(seed, px, crate::layout::GATHER_STREAM | ray);
    let (u1, u2) = (rng_next(&mut rng), rng_next(&mut rng));
    let mut d = crate::sampling::sample_cosine(n1, u1, u2);
    let mut o = offset_origin(first, n1, d, floor);
    let mut throughput = Vec3::ONE;
    for _ in 0..=max_depth {
        let (shape, _, p, n) = closest_hit(scene, o, d)?;
        let material = scene.shapes[shape].material;
        let entering = n.dot(d) < 0.0;
        let nf = if entering { n } else { -n };
        if fade > 0.0 {
            let Material::Diffuse { .. } = scene.materials[material] else {
                return None;
            };
            let left_out = 1.0 - super::igi::bound((p - first).length(), fade);
            if left_out <= 0.0 {
                return None;
            }
            throughput = Vec3::splat(left_out);
        }
        let ior = match scene.materials[material] {
            Material::Emitter { .. } => return None,
            Material::Diffuse { .. } => {
                return Some(GatherHit {
                    position: p,
                    normal: nf,
                    material,
                    throughput,
                })
            }
            Material::Mirror { reflectance } => {
                throughput *= reflectance;
                0.0
            }
            Material::Glass { ior } => ior,
            m @ Material::Conductor { .. } if m.is_glossy() => {
                let ms = facing_shading_normal(&scene.shapes[shape], p, n, d);
                let b = rough_metal(&m).expect("a rough metal");
                let v1 = rng_next(&mut rng);
                let s = bsdf_sample(
                    &b,
                    &Frame::around(ms),
                    -d,
                    Vec2::new(v1, rng_next(&mut rng)),
                );
                if s.lobe == 0 || s.wi.dot(nf) <= 0.0 {
                    return None;
                }
                throughput *= s.weight;
                d = s.wi;
                o = offset_origin(p, nf, d, floor);
                continue;
            }
            Material::Conductor { .. } => 0.0,
        };
        let u = if ior > 0.0 { rng_next(&mut rng) } else { 0.0 };
        let ms = facing_shading_normal(&scene.shapes[shape], p, n, d);
        let (next, used) = if scene.shapes[shape].normals.is_some() {
            specular_shaded(d, nf, ms, ior, entering, u)
        } else {
            (specular_about(d, nf, ior, entering, u), false)
        };
        throughput *=
            smooth_metal_factor(&scene.materials[material], d, if used { ms } else { nf });
        throughput *= radiance_refraction_scale(next, nf, ior, entering);
        let next = next.normalize();
        d = next;
        o = offset_origin(p, nf, d, floor);
    }
    None
}

/// The radiance a gather ray brings back: the global map's estimate at its
/// hit, throughput * albedo / pi * sum(power) / (pi r^2), r as compose.frag takes it.
pub fn gathered_radiance(
    scene: &Scene,
    map: &CpuPhotonMap,
    hit: &GatherHit,
    k: u32,
    max_radius: f32,
) -> Vec3 {
    let Material::Diffuse { albedo } = scene.materials[hit.material] else {
        return Vec3::ZERO;
    };
    let irradiance = knn_grid(map, hit.position, k, max_radius).irradiance(k, max_radius);
    hit.throughput * albedo / std::f32::consts::PI * irradiance
}
