//! A CPU ray tracer of the same light transport as the GPU passes, but
//! deterministic: glass *splits* into both Fresnel-weighted branches where the
//! GPU chooses one at random. Averaging GPU renders over seeds must converge to
//! this (tests/ray_tracer.rs), which is what shows the stochastic choice is unbiased.

use glam::Vec3;

use crate::scene::{Geometry, Light, Material, Scene};

use super::intersect::intersect_geometry;

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

/// Fresnel reflectance (glsl/common/fresnel.glsl) and the transmitted cosine.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> (f32, f32) {
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t >= 1.0 {
        return (1.0, 0.0);
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    (0.5 * (rs * rs + rp * rp), cos_t)
}

/// Expected radiance along a ray: direct light (area lights by a `grid` x `grid`
/// midpoint rule), emitters, and every specular branch, to `depth_left` bounces.
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
    match scene.materials[scene.shapes[i].material] {
        Material::Emitter { radiance, normal } => deterministic(if d.dot(normal) < 0.0 {
            radiance
        } else {
            Vec3::ZERO
        }),
        Material::Diffuse { albedo } => {
            let origin = p + offset_scale(p, floor) * nf;
            let mut sum = Vec3::ZERO;
            for l in &scene.lights {
                match *l {
                    Light::Point {
                        position,
                        intensity,
                    } => {
                        let to = position - origin;
                        let dist = to.length();
                        let wi = to / dist;
                        let cos_x = nf.dot(wi);
                        if cos_x > 0.0 && !occluded(scene, origin, wi, dist) {
                            sum += intensity * cos_x / (dist * dist);
                        }
                    }
                    Light::Area {
                        corner,
                        edge1,
                        edge2,
                        normal,
                        radiance,
                    } => {
                        let area = edge1.cross(edge2).length();
                        let mut ls = Vec3::ZERO;
                        for a in 0..grid {
                            for b in 0..grid {
                                let q = corner
                                    + (a as f32 + 0.5) / grid as f32 * edge1
                                    + (b as f32 + 0.5) / grid as f32 * edge2;
                                let to = q - origin;
                                let dist = to.length();
                                let wi = to / dist;
                                let (cx, cl) = (nf.dot(wi), -normal.dot(wi));
                                if cx > 0.0
                                    && cl > 0.0
                                    && !occluded(
                                        scene,
                                        origin,
                                        wi,
                                        dist - 2.0 * offset_scale(q, floor),
                                    )
                                {
                                    ls += radiance * cx * cl / (dist * dist);
                                }
                            }
                        }
                        sum += ls * area / (grid * grid) as f32;
                    }
                }
            }
            deterministic(albedo / std::f32::consts::PI * sum)
        }
        Material::Mirror { reflectance } => {
            if depth_left == 0 {
                return (Vec3::ZERO, Vec3::ZERO);
            }
            let r = (d - 2.0 * d.dot(nf) * nf).normalize();
            let origin = p + offset_scale(p, floor) * nf;
            let (m1, m2) = expected_moments(scene, origin, r, depth_left - 1, grid);
            (reflectance * m1, reflectance * reflectance * m2)
        }
        Material::Glass { ior } => {
            if depth_left == 0 {
                return (Vec3::ZERO, Vec3::ZERO);
            }
            let entering = n.dot(d) < 0.0;
            let eta = if entering { 1.0 / ior } else { ior };
            let cos_i = -d.dot(nf);
            let (f, cos_t) = fresnel_dielectric(cos_i, eta);
            let r = (d - 2.0 * d.dot(nf) * nf).normalize();
            let s = offset_scale(p, floor);
            let (r1, r2) = expected_moments(scene, p + s * nf, r, depth_left - 1, grid);
            let (mut m1, mut m2) = (f * r1, f * r2);
            if f < 1.0 {
                let t = (eta * d + (eta * cos_i - cos_t) * nf).normalize();
                let (t1, t2) = expected_moments(scene, p - s * nf, t, depth_left - 1, grid);
                m1 += (1.0 - f) * t1;
                m2 += (1.0 - f) * t2;
            }
            (m1, m2)
        }
    }
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
