//! A CPU ray tracer of the same light transport as the GPU passes, but
//! deterministic: glass *splits* into both Fresnel-weighted branches where the
//! GPU chooses one at random. Averaging GPU renders over seeds must converge to
//! this (tests/gpu/ray_tracer.rs), which is what shows the stochastic choice is unbiased.

use glam::Vec3;

use crate::scene::{triangle_area, Geometry, Light, Material, Scene, Shape};

use crate::scene::pack::PackedScene;

use super::bsdf::smooth_metal_factor;
use super::intersect::intersect_geometry;
use super::light::{area_light_point, sample_light_triangle};
use super::random::{rng_init, rng_next};
use super::shading::{
    facing_shading_normal, fresnel_dielectric, radiance_refraction_scale, specular_about,
};

/// Closest hit: (shape index, t, point, geometric normal).
pub fn closest_hit(scene: &Scene, o: Vec3, d: Vec3) -> Option<(usize, f32, Vec3, Vec3)> {
    let mut best: Option<(usize, f32, f32, f32)> = None;
    for (i, s) in scene.shapes.iter().enumerate() {
        if let Some((t, u, v)) = intersect_geometry(&s.geometry, o, d) {
            if best.is_none_or(|b| t < b.1) {
                best = Some((i, t, u, v));
            }
        }
    }
    let (i, t, u, v) = best?;
    let (p, n) = surface_point(&scene.shapes[i].geometry, o, d, t, u, v);
    Some((i, t, p, n))
}

/// The hit point rebuilt from surface parameters, as glsl/common/scene.glsl does.
pub fn surface_point(g: &Geometry, o: Vec3, d: Vec3, t: f32, u: f32, v: f32) -> (Vec3, Vec3) {
    match *g {
        Geometry::Sphere { center, radius } => {
            let n = (o + t * d - center).normalize();
            (center + radius * n, n)
        }
        Geometry::Cylinder {
            base, axis, radius, ..
        } => {
            let on_axis = base + u * axis;
            let r = o + t * d - on_axis;
            let n = (r - r.dot(axis) * axis).normalize();
            (on_axis + radius * n, n)
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
            (1.0 - u - v) * v0 + u * v1 + v * v2,
            (v1 - v0).cross(v2 - v0).normalize(),
        ),
    }
}

/// 2^-18, as glsl/common/scene.glsl.
pub const OFFSET_RELATIVE: f32 = 3.814_697e-6;

pub fn offset_scale(p: Vec3, offset_floor: f32) -> f32 {
    OFFSET_RELATIVE * p.abs().max_element() + offset_floor
}

pub fn occluded(scene: &Scene, o: Vec3, d: Vec3, t_max: f32) -> bool {
    scene
        .shapes
        .iter()
        .any(|s| intersect_geometry(&s.geometry, o, d).is_some_and(|h| h.0 < t_max))
}

/// A point light's I cos / r^2 at `origin` (facing normal `nf`), the
/// cosine by `cosine(wi, cos_x)` (the shading normal's where one is given);
/// zero behind `nf` or shadowed.
pub fn point_light(
    scene: &Scene,
    origin: Vec3,
    nf: Vec3,
    (position, intensity): (Vec3, Vec3),
    cosine: impl Fn(Vec3, f32) -> f32,
) -> Vec3 {
    let to = position - origin;
    let dist = to.length();
    let wi = to / dist;
    let cos_x = nf.dot(wi);
    if cos_x > 0.0 && !occluded(scene, origin, wi, dist) {
        intensity * cosine(wi, cos_x) / (dist * dist)
    } else {
        Vec3::ZERO
    }
}

/// Toward point `q` of an emitter (normal `normal`) from `origin` (facing
/// normal `nf`): (wi, cos_x, cos_l, dist) when each faces the other and
/// nothing lies between (the shadow ray stops short of q by its offsets).
pub fn toward_emitter(
    scene: &Scene,
    origin: Vec3,
    nf: Vec3,
    (q, normal): (Vec3, Vec3),
    floor: f32,
) -> Option<(Vec3, f32, f32, f32)> {
    let to = q - origin;
    let dist = to.length();
    let wi = to / dist;
    let (cos_x, cos_l) = (nf.dot(wi), -normal.dot(wi));
    let seen = cos_x > 0.0
        && cos_l > 0.0
        && !occluded(scene, origin, wi, dist - 2.0 * offset_scale(q, floor));
    seen.then_some((wi, cos_x, cos_l, dist))
}

/// Expected radiance along a ray: direct light (area lights by a `grid` x `grid`
/// midpoint rule; a `Triangles` light by that rule on each of its triangles),
/// emitters, and every specular branch, to `depth_left` bounces.
pub fn expected_radiance(scene: &Scene, o: Vec3, d: Vec3, depth_left: u32, grid: u32) -> Vec3 {
    expected_moments(scene, o, d, depth_left, grid).0
}

/// First and second moments of the GPU's one-path estimate along a ray: glass
/// picks reflection with probability F, so both moments mix the branches with
/// weights F and 1 - F; variance = second - first^2, exactly.
pub fn expected_moments(
    scene: &Scene,
    o: Vec3,
    d: Vec3,
    depth_left: u32,
    grid: u32,
) -> (Vec3, Vec3) {
    let floor = 1e-6 * scene.size();
    let Some((i, _t, p, n)) = closest_hit(scene, o, d) else {
        return (Vec3::ZERO, Vec3::ZERO);
    };
    let deterministic = |l: Vec3| (l, l * l);
    let nf = if n.dot(d) < 0.0 { n } else { -n };
    let shape = &scene.shapes[i];
    let ms = facing_shading_normal(shape, p, n, d);
    match scene.materials[shape.material] {
        Material::Emitter { radiance, normal } => {
            deterministic(if d.dot(normal.unwrap_or(n)) < 0.0 {
                radiance
            } else {
                Vec3::ZERO
            })
        }
        Material::Diffuse { albedo } => {
            let origin = p + offset_scale(p, floor) * nf;
            let shading = shape.normals.is_some().then_some(ms);
            let sum = direct_irradiance(scene, origin, nf, shading, grid);
            deterministic(albedo / std::f32::consts::PI * sum)
        }
        Material::Mirror { .. } | Material::Glass { .. } if depth_left == 0 => {
            (Vec3::ZERO, Vec3::ZERO)
        }
        Material::Mirror { reflectance } => {
            let (m1, m2) = specular_moments(scene, (p, n, nf, ms), shape, d, 0.0, depth_left, grid);
            (reflectance * m1, reflectance * reflectance * m2)
        }
        Material::Glass { ior } => {
            specular_moments(scene, (p, n, nf, ms), shape, d, ior, depth_left, grid)
        }
        Material::Conductor { alpha, .. } if alpha > 0.0 => {
            panic!("expected_moments follows smooth surfaces only, not a rough metal")
        }
        Material::Conductor { .. } if depth_left == 0 => (Vec3::ZERO, Vec3::ZERO),
        metal @ Material::Conductor { .. } => {
            // One branch, about the shading normal where its reflection
            // leaves above the geometric surface (specular_shaded's rule).
            let about_ms = shape.normals.is_some()
                && d.dot(ms) < 0.0
                && specular_about(d, ms, 0.0, true, 0.0).dot(nf) > 0.0;
            let f = smooth_metal_factor(&metal, d, if about_ms { ms } else { nf });
            let (m1, m2) = specular_moments(scene, (p, n, nf, ms), shape, d, 0.0, depth_left, grid);
            (f * m1, f * f * m2)
        }
    }
}

/// The branches of a mirror (ior 0) or glass event about the normal m facing
/// d: (probability, direction), as `specular_about` picks them.
fn branches(d: Vec3, m: Vec3, ior: f32, entering: bool) -> Vec<(f32, Vec3)> {
    if ior == 0.0 {
        return vec![(1.0, specular_about(d, m, 0.0, entering, 0.0))];
    }
    let eta = if entering { 1.0 / ior } else { ior };
    let (f, _) = fresnel_dielectric(-d.dot(m), eta);
    let mut out = vec![(f, specular_about(d, m, ior, entering, -1.0))];
    if f < 1.0 {
        out.push((1.0 - f, specular_about(d, m, ior, entering, 2.0)));
    }
    out
}

/// The moments after a mirror or glass event at p (geometric normal n, and
/// facing the ray: nf, shading ms): every branch the GPU may take, each about
/// the shading normal where it lands on the right side of the surface, else
/// the whole event redone about nf (`specular_shaded`).
fn specular_moments(
    scene: &Scene,
    (p, n, nf, ms): (Vec3, Vec3, Vec3, Vec3),
    shape: &Shape,
    d: Vec3,
    ior: f32,
    depth_left: u32,
    grid: u32,
) -> (Vec3, Vec3) {
    let entering = n.dot(d) < 0.0;
    let geometric = || branches(d, nf, ior, entering);
    let taken: Vec<(f32, Vec3)> = if shape.normals.is_some() && d.dot(ms) < 0.0 {
        branches(d, ms, ior, entering)
            .into_iter()
            .flat_map(|(w, next)| {
                let reflected = next.dot(ms) > 0.0;
                if reflected == (next.dot(nf) > 0.0) {
                    vec![(w, next)]
                } else {
                    geometric().into_iter().map(|(v, g)| (w * v, g)).collect()
                }
            })
            .collect()
    } else {
        geometric()
    };
    let s = offset_scale(p, 1e-6 * scene.size());
    let (mut m1, mut m2) = (Vec3::ZERO, Vec3::ZERO);
    for (w, next) in taken {
        // Radiance's (eta_i / eta_t)^2 where the branch refracts.
        let scale = radiance_refraction_scale(next, nf, ior, entering);
        let next = next.normalize();
        let origin = p + if next.dot(nf) >= 0.0 { s } else { -s } * nf;
        let (b1, b2) = expected_moments(scene, origin, next, depth_left - 1, grid);
        m1 += w * scale * b1;
        m2 += w * scale * scale * b2;
    }
    (m1, m2)
}

/// Irradiance-like sum at `origin` (facing normal nf): sum over lights of
/// L cos_s cos_l / r^2 dA, with cos_s the shading normal's (when given; the
/// light must still be in front of nf).
fn direct_irradiance(
    scene: &Scene,
    origin: Vec3,
    nf: Vec3,
    shading: Option<Vec3>,
    grid: u32,
) -> Vec3 {
    let floor = 1e-6 * scene.size();
    let cosine = |wi: Vec3, cos_x: f32| shading.map_or(cos_x, |ms| ms.dot(wi).max(0.0));
    // L cos_s cos_l / r^2 from point q of a surface of normal `normal`.
    let from = |q: Vec3, normal: Vec3, radiance: Vec3| {
        toward_emitter(scene, origin, nf, (q, normal), floor)
            .map_or(Vec3::ZERO, |(wi, cx, cl, dist)| {
                radiance * (cosine(wi, cx) * cl / (dist * dist))
            })
    };
    let cells = || {
        let g = grid as f32;
        (0..grid)
            .flat_map(move |a| (0..grid).map(move |b| ((a as f32 + 0.5) / g, (b as f32 + 0.5) / g)))
    };
    let per_cell = 1.0 / (grid * grid) as f32;
    let mut sum = Vec3::ZERO;
    for l in &scene.lights {
        match *l {
            Light::Point {
                position,
                intensity,
            } => sum += point_light(scene, origin, nf, (position, intensity), cosine),
            Light::Area {
                normal, radiance, ..
            } => {
                let ls: Vec3 = cells()
                    .map(|(u, v)| from(area_light_point(l, u, v), normal, radiance))
                    .sum();
                sum += ls * l.area(&scene.shapes) * per_cell;
            }
            Light::Triangles {
                first,
                count,
                radiance,
            } => {
                for shape in &scene.shapes[first..first + count] {
                    let Geometry::Triangle { v0, v1, v2 } = shape.geometry else {
                        continue;
                    };
                    let area = triangle_area(&shape.geometry);
                    if area <= 0.0 {
                        continue;
                    }
                    let normal = (v1 - v0).cross(v2 - v0).normalize();
                    // The midpoint rule on the unit square, mapped to the
                    // triangle by the GPU's area-uniform map.
                    let ls: Vec3 = cells()
                        .map(|(u, v)| {
                            let s = u.sqrt();
                            let q = (1.0 - s) * v0 + (v * s) * v1 + (s - v * s) * v2;
                            from(q, normal, radiance)
                        })
                        .sum();
                    sum += ls * area * per_cell;
                }
            }
        }
    }
    sum
}

/// The eye ray through pixel (x, y), y counted from the top row.
pub fn eye_ray(scene: &Scene, width: u32, height: u32, x: u32, y: u32) -> (Vec3, Vec3) {
    eye_ray_at(scene, width, height, x as f32 + 0.5, y as f32 + 0.5)
}

/// The eye ray through image point (fx, fy) in pixels from the top-left corner.
pub fn eye_ray_at(scene: &Scene, width: u32, height: u32, fx: f32, fy: f32) -> (Vec3, Vec3) {
    let cam = &scene.camera;
    let (u, v, w) = cam.basis();
    let tan_v = (cam.vfov_degrees.to_radians() * 0.5).tan();
    let aspect = width as f32 / height as f32;
    let nx = fx / width as f32 * 2.0 - 1.0;
    let ny = (height as f32 - fy) / height as f32 * 2.0 - 1.0;
    let d = -w + nx * tan_v * aspect * u + ny * tan_v * v;
    (cam.position, d.normalize())
}

/// glsl/render/direct.frag for the eye ray (o, d) of GL pixel `px` (y up)
/// at depth 0, drawing the same random numbers from the render's `seed`:
/// the radiance the pass adds over all `shadow_rays` samples per area light
/// (path throughput 1). Area lights are the parallelogram's stratified
/// point, or a `Triangles` light's triangle picked by area and a uniform
/// point in it (`light::sample_light_triangle`, the twin of the shader's).
pub fn direct_light_sampled(
    scene: &Scene,
    packed: &PackedScene,
    seed: u32,
    px: [u32; 2],
    shadow_rays: u32,
    (o, d): (Vec3, Vec3),
) -> Vec3 {
    let floor = 1e-6 * scene.size();
    let Some((i, _t, p, n)) = closest_hit(scene, o, d) else {
        return Vec3::ZERO;
    };
    let shape = &scene.shapes[i];
    let albedo = match scene.materials[shape.material] {
        Material::Emitter { radiance, normal } => {
            return if d.dot(normal.unwrap_or(n)) < 0.0 {
                radiance
            } else {
                Vec3::ZERO
            };
        }
        Material::Diffuse { albedo } => albedo,
        _ => return Vec3::ZERO,
    };
    let nf = if n.dot(d) < 0.0 { n } else { -n };
    let shaded = shape.normals.is_some();
    let nsf = facing_shading_normal(shape, p, n, d);
    let origin = p + offset_scale(p, floor) * nf;
    let cosine = |wi: Vec3, cos_x: f32| if shaded { nsf.dot(wi).max(0.0) } else { cos_x };
    let (nx, _) = crate::sampling::strata(shadow_rays);
    let strata_y = shadow_rays / nx;
    let row = |l: usize, k: usize| glam::Vec4::from(packed.lights[l * 6 + k]);
    let mut sum = Vec3::ZERO;
    for (l, light) in scene.lights.iter().enumerate() {
        if let Light::Point {
            position,
            intensity,
        } = *light
        {
            sum += point_light(scene, origin, nf, (position, intensity), cosine);
            continue;
        }
        let emitted = row(l, 4).truncate();
        let (mut light_sum, mut area) = (Vec3::ZERO, 0.0);
        for s in 0..shadow_rays {
            let mut rng = rng_init(seed, px, 0x4000_0000 | ((l as u32) << 12) | s);
            let su = ((s % nx) as f32 + rng_next(&mut rng)) / nx as f32;
            let sv = ((s / nx) as f32 + rng_next(&mut rng)) / strata_y as f32;
            let (q, light_normal) = match *light {
                Light::Triangles { .. } => {
                    area = row(l, 1).z;
                    let (q, normal, _) = sample_light_triangle(packed, l, su, sv);
                    (q, normal)
                }
                _ => {
                    let (a, e1, e2) = (
                        row(l, 1).truncate(),
                        row(l, 2).truncate(),
                        row(l, 3).truncate(),
                    );
                    area = e1.cross(e2).length();
                    (
                        a + su * e1 + sv * e2,
                        Vec3::new(row(l, 0).y, row(l, 0).z, row(l, 0).w),
                    )
                }
            };
            let Some((wi, cos_x, cos_l, dist)) =
                toward_emitter(scene, origin, nf, (q, light_normal), floor)
            else {
                continue;
            };
            light_sum += emitted * (cosine(wi, cos_x) * cos_l / (dist * dist));
        }
        sum += light_sum * (area / shadow_rays as f32);
    }
    albedo / std::f32::consts::PI * sum
}
