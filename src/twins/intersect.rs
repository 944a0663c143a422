//! The formulas of glsl/common/intersect.glsl in f32 Rust, line for line.

use glam::Vec3;

use crate::scene::Geometry;

/// (t, u, v) of a hit along a unit direction.
pub type Hit = Option<(f32, f32, f32)>;

pub fn intersect_sphere(o: Vec3, d: Vec3, center: Vec3, radius: f32) -> Hit {
    let f = o - center;
    let b = -f.dot(d);
    let l = f + b * d;
    let disc = radius * radius - l.dot(l);
    if disc < 0.0 {
        return None;
    }
    let c = f.dot(f) - radius * radius;
    let q = b + if b >= 0.0 { disc.sqrt() } else { -disc.sqrt() };
    let t0 = if q != 0.0 { c / q } else { 0.0 };
    let t1 = q;
    let (tn, tf) = (t0.min(t1), t0.max(t1));
    let t = if tn > 0.0 { tn } else { tf };
    (t > 0.0).then_some((t, 0.0, 0.0))
}

pub fn intersect_cylinder(
    o: Vec3,
    d: Vec3,
    base: Vec3,
    axis: Vec3,
    radius: f32,
    height: f32,
) -> Hit {
    let f = o - base;
    let fp = f - f.dot(axis) * axis;
    let dp = d - d.dot(axis) * axis;
    let a = dp.dot(dp);
    if a < 1e-12 {
        return None;
    }
    let cr = fp.cross(dp);
    let disc = radius * radius * a - cr.dot(cr);
    if disc < 0.0 {
        return None;
    }
    let b = -fp.dot(dp);
    let c = fp.dot(fp) - radius * radius;
    let q = b + if b >= 0.0 { disc.sqrt() } else { -disc.sqrt() };
    let ta = q / a;
    let tb = if q != 0.0 { c / q } else { 0.0 };
    let (tn, tf) = (ta.min(tb), ta.max(tb));
    let hn = (f + tn * d).dot(axis);
    if tn > 0.0 && (0.0..=height).contains(&hn) {
        return Some((tn, hn, 0.0));
    }
    let hf = (f + tf * d).dot(axis);
    if tf > 0.0 && (0.0..=height).contains(&hf) {
        return Some((tf, hf, 0.0));
    }
    None
}

pub fn intersect_parallelogram(o: Vec3, d: Vec3, corner: Vec3, e1: Vec3, e2: Vec3) -> Hit {
    let pvec = d.cross(e2);
    let det = e1.dot(pvec);
    if det == 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    let tvec = o - corner;
    let u = tvec.dot(pvec) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let qvec = tvec.cross(e1);
    let v = d.dot(qvec) * inv_det;
    if !(0.0..=1.0).contains(&v) {
        return None;
    }
    let t = e2.dot(qvec) * inv_det;
    (t > 0.0).then_some((t, u, v))
}

/// The ray prepared for the watertight triangle test, as `SceneRay` in GLSL.
#[derive(Clone, Copy, Debug)]
pub struct ShearedRay {
    pub o: Vec3,
    pub d: Vec3,
    /// 1 / d, zero components replaced by +-1e30 (for box tests).
    pub inv: Vec3,
    pub k: [usize; 3],
    pub s: Vec3,
}

impl ShearedRay {
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let inv = Vec3::from_array(d.to_array().map(|c| {
            if c.abs() < 1e-30 {
                if c < 0.0 {
                    -1e30
                } else {
                    1e30
                }
            } else {
                1.0 / c
            }
        }));
        let a = d.abs();
        let kz = if a.x > a.y {
            if a.x > a.z {
                0
            } else {
                2
            }
        } else if a.y > a.z {
            1
        } else {
            2
        };
        let kx = if kz == 2 { 0 } else { kz + 1 };
        let ky = if kx == 2 { 0 } else { kx + 1 };
        let (kx, ky) = if d[kz] < 0.0 { (ky, kx) } else { (kx, ky) };
        let sz = 1.0 / d[kz];
        Self {
            o,
            d,
            inv,
            k: [kx, ky, kz],
            s: Vec3::new(d[kx] * sz, d[ky] * sz, sz),
        }
    }
}

/// a b - c d with its exact sign: a float 0 is recomputed in f64, where the products are exact.
fn edge_function(a: f32, b: f32, c: f32, d: f32) -> f32 {
    let e = a * b - c * d;
    if e != 0.0 {
        e
    } else {
        (a as f64 * b as f64 - c as f64 * d as f64) as f32
    }
}

/// Watertight (Woop, Benthin and Wald 2013); (u, v) weigh v1 and v2.
pub fn intersect_triangle(r: &ShearedRay, v0: Vec3, v1: Vec3, v2: Vec3) -> Hit {
    let [kx, ky, kz] = r.k;
    let (a, b, c) = (v0 - r.o, v1 - r.o, v2 - r.o);
    let (ax, ay) = (a[kx] - r.s.x * a[kz], a[ky] - r.s.y * a[kz]);
    let (bx, by) = (b[kx] - r.s.x * b[kz], b[ky] - r.s.y * b[kz]);
    let (cx, cy) = (c[kx] - r.s.x * c[kz], c[ky] - r.s.y * c[kz]);
    let u = edge_function(cx, by, cy, bx);
    let v = edge_function(ax, cy, ay, cx);
    let w = edge_function(bx, ay, by, ax);
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    if det == 0.0 {
        return None;
    }
    let t_scaled = u * (r.s.z * a[kz]) + v * (r.s.z * b[kz]) + w * (r.s.z * c[kz]);
    if (if det < 0.0 { -t_scaled } else { t_scaled }) <= 0.0 {
        return None;
    }
    let inv_det = 1.0 / det;
    Some((t_scaled * inv_det, v * inv_det, w * inv_det))
}

/// The hit of a prepared ray with one primitive.
pub fn intersect_geometry_ray(g: &Geometry, r: &ShearedRay) -> Hit {
    match *g {
        Geometry::Triangle { v0, v1, v2 } => intersect_triangle(r, v0, v1, v2),
        _ => intersect_geometry(g, r.o, r.d),
    }
}

pub fn intersect_geometry(g: &Geometry, o: Vec3, d: Vec3) -> Hit {
    match *g {
        Geometry::Sphere { center, radius } => intersect_sphere(o, d, center, radius),
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => intersect_cylinder(o, d, base, axis, radius, height),
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => intersect_parallelogram(o, d, corner, edge1, edge2),
        Geometry::Triangle { v0, v1, v2 } => intersect_triangle(&ShearedRay::new(o, d), v0, v1, v2),
    }
}

/// How far (in f64) a ray passes from the boundary of the primitive's hit test:
/// near zero, f32 rounding may decide either way, so twins may disagree there.
pub fn boundary_margin(g: &Geometry, o: Vec3, d: Vec3) -> f64 {
    let (o, d) = (o.as_dvec3(), d.as_dvec3());
    match *g {
        Geometry::Sphere { center, radius } => {
            let f = o - center.as_dvec3();
            let l = f - f.dot(d) * d;
            let r = radius as f64;
            // Tangency, and an origin on the surface.
            ((r * r - l.dot(l)).abs() / (r * r)).min((f.length() - r).abs() / r)
        }
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            let (b, a, r, h) = (
                base.as_dvec3(),
                axis.as_dvec3(),
                radius as f64,
                height as f64,
            );
            let f = o - b;
            let fp = f - f.dot(a) * a;
            let dp = d - d.dot(a) * a;
            let mut m = (fp.length() - r).abs() / r;
            let aa = dp.dot(dp);
            if aa > 0.0 {
                let cr = fp.cross(dp);
                m = m.min((r * r * aa - cr.dot(cr)).abs() / (r * r * aa));
                // Distance of each root's height from the rim.
                let bb = -fp.dot(dp);
                let disc = (r * r * aa - cr.dot(cr)).max(0.0).sqrt();
                for t in [(bb - disc) / aa, (bb + disc) / aa] {
                    let hh = (f + t * d).dot(a);
                    m = m.min(hh.abs().min((hh - h).abs()) / h.max(r));
                    m = m.min(t.abs() / (r + f.length()));
                }
            } else {
                m = 0.0;
            }
            m
        }
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => planar_margin(
            o,
            d,
            corner.as_dvec3(),
            edge1.as_dvec3(),
            edge2.as_dvec3(),
            false,
        ),
        Geometry::Triangle { v0, v1, v2 } => {
            let v0 = v0.as_dvec3();
            planar_margin(o, d, v0, v1.as_dvec3() - v0, v2.as_dvec3() - v0, true)
        }
    }
}

fn planar_margin(
    o: glam::DVec3,
    d: glam::DVec3,
    c: glam::DVec3,
    e1: glam::DVec3,
    e2: glam::DVec3,
    triangle: bool,
) -> f64 {
    let n = e1.cross(e2);
    let det = d.dot(n).abs() / n.length();
    if det < 1e-3 {
        return 0.0; // grazing: the plane test itself is ill-conditioned
    }
    let pvec = d.cross(e2);
    let inv = 1.0 / e1.dot(pvec);
    let tvec = o - c;
    let u = tvec.dot(pvec) * inv;
    let v = d.dot(tvec.cross(e1)) * inv;
    let t = e2.dot(tvec.cross(e1)) * inv;
    let mut m = u.abs().min((1.0 - u).abs()).min(v.abs());
    m = m.min(if triangle {
        (1.0 - u - v).abs()
    } else {
        (1.0 - v).abs()
    });
    m.min(t.abs() / (tvec.length() + e1.length() + e2.length()))
}
