//! Twin of `sample_light_triangle` in glsl/common/scene.glsl: a point
//! uniform over a triangle-mesh light, shared by the photon tracer's emission
//! and the ray tracer's sampled direct light; and a point of an area light,
//! shared by the ray tracer's and the path tracer's direct light.

use glam::{Vec3, Vec4};

use crate::scene::pack::PackedScene;
use crate::scene::Light;

/// The point of an `Area` light's parallelogram at (u, v) in [0, 1)^2 (the
/// origin for another kind of light).
pub fn area_light_point(light: &Light, u: f32, v: f32) -> Vec3 {
    let Light::Area {
        corner,
        edge1,
        edge2,
        ..
    } = *light
    else {
        return Vec3::ZERO;
    };
    corner + u * edge1 + v * edge2
}

/// glsl/common/scene.glsl `sample_light_triangle`: a point of the
/// LIGHT_TRIANGLES light l uniform over its area (u1 picks the triangle by
/// area and is reused within it), its triangle's unit normal, its primitive.
pub fn sample_light_triangle(
    packed: &PackedScene,
    l: usize,
    u1: f32,
    u2: f32,
) -> (Vec3, Vec3, usize) {
    let range = Vec4::from(packed.lights[l * 6 + 1]);
    let first = range.x as usize;
    let cdf = |k: usize| packed.light_triangles[first + k][0];
    let (mut lo, mut hi) = (0i32, range.y as i32 - 1);
    while lo < hi {
        let mid = (lo + hi) / 2;
        if u1 < cdf(mid as usize) {
            hi = mid;
        } else {
            lo = mid + 1;
        }
    }
    let k = lo as usize;
    let below = if k > 0 { cdf(k - 1) } else { 0.0 };
    let u = ((u1 - below) / (cdf(k) - below)).clamp(0.0, 1.0);
    let prim = packed.light_triangles[first + k][1] as usize;
    let vertex = |i: usize| Vec4::from(packed.primitives[prim * 4 + i]).truncate();
    let (a, b, c) = (vertex(1), vertex(2), vertex(3));
    let normal = (b - a).cross(c - a).normalize();
    let s = u.sqrt();
    (
        (1.0 - s) * a + (u2 * s) * b + (s - u2 * s) * c,
        normal,
        prim,
    )
}
