//! Twins of photon differentials and the footprint BVH
//! (glsl/photon/differentials.frag, footprint_keys.frag, footprints.frag,
//! footprint_leaves.frag, footprint_reduce.frag; glsl/common/footprint.glsl;
//! glsl/render/footprint_gather.frag), line for line, on records read back
//! from the GPU.

use glam::Vec3;

use crate::layout::{COVERAGE_CROSSINGS, COVERAGE_NORMAL_COS, FOOTPRINT_THICKNESS};
use crate::photon::differentials::FootprintOptions;
use crate::scene::pack::PackedScene;
use crate::scene::{Geometry, Light, Material, Scene};

use super::photon::{basis_around, primitive_normal, PhotonRecord};
use super::ray_trace::{closest_hit, offset_scale};
use super::shading::{fresnel_dielectric, shading_normal, specular_shaded};

/// Two positional and two directional differentials (units of Delta).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Differentials {
    pub dp: [Vec3; 2],
    pub dd: [Vec3; 2],
}

/// One record's differentials: dp at its hit, and as the photon leaves.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RecordDifferentials {
    pub axis: [Vec3; 2],
    /// Reflected diffusely before this hit.
    pub diffuse_at_hit: bool,
    pub out: Differentials,
    pub diffuse_out: bool,
    /// The geometric normal at the hit, facing the photon's arrival.
    pub normal: Vec3,
}

/// Emission: the orthonormal pair about d scaled by the square roots of the
/// light's [directional, positional] measures.
pub fn emission(d: Vec3, [directional, positional]: [f32; 2]) -> Differentials {
    let (t0, t1) = basis_around(d);
    let (s, v) = (directional.sqrt(), positional.sqrt());
    Differentials {
        dp: [v * t0, v * t1],
        dd: [s * t0, s * t1],
    }
}

/// Igehy's transfer to the hit p (normal nf) from `origin` along unit d.
pub fn transfer(diff: &Differentials, origin: Vec3, p: Vec3, d: Vec3, nf: Vec3) -> [Vec3; 2] {
    let t = (p - origin).dot(d);
    [0, 1].map(|k| {
        let moved = diff.dp[k] + t * diff.dd[k];
        moved - moved.dot(nf) / d.dot(nf) * d
    })
}

/// Re-emission at a diffuse hit (equation 13): roulette survival q widens
/// the footprint to area / q; the new directional pair is orthonormal about
/// `next` and the positional one v times it.
pub fn reemit(dp_hit: [Vec3; 2], q: f32, next: Vec3) -> Differentials {
    let v = (dp_hit[0].cross(dp_hit[1]).length() / q).sqrt();
    let (t0, t1) = basis_around(next);
    Differentials {
        dp: [v * t0, v * t1],
        dd: [t0, t1],
    }
}

/// Reflection of directional differentials about unit m (facing d), whose
/// own differentials are dn.
pub fn reflect(d: Vec3, m: Vec3, dd: [Vec3; 2], dn: [Vec3; 2]) -> [Vec3; 2] {
    let dm = d.dot(m);
    let mut out = dd;
    for k in 0..2 {
        let ddm = dd[k].dot(m) + d.dot(dn[k]);
        out[k] = dd[k] - 2.0 * (dm * dn[k] + ddm * m);
    }
    out
}

/// Refraction of directional differentials with eta = n_i / n_t; cos_t is
/// the transmitted cosine.
pub fn refract(d: Vec3, m: Vec3, eta: f32, cos_t: f32, dd: [Vec3; 2], dn: [Vec3; 2]) -> [Vec3; 2] {
    let dm = d.dot(m);
    let mu = -eta * dm - cos_t;
    let mut out = dd;
    for k in 0..2 {
        let ddm = dd[k].dot(m) + d.dot(dn[k]);
        let dmu = (-eta - eta * eta * dm / cos_t) * ddm;
        out[k] = eta * dd[k] + mu * dn[k] + dmu * m;
    }
    out
}

/// The normal's differential along dp on a sphere or cylinder (0 elsewhere).
pub fn normal_differential(g: &Geometry, dp: Vec3, side: f32) -> Vec3 {
    match *g {
        Geometry::Sphere { radius, .. } => side * dp / radius,
        Geometry::Cylinder { axis, radius, .. } => side * (dp - dp.dot(axis) * axis) / radius,
        _ => Vec3::ZERO,
    }
}

/// The light a frame-0 record left from (glsl `emitting_light`): the point
/// light at p, the area light whose primitive it left, or the triangle light
/// holding that primitive.
fn emitting_light(scene: &Scene, packed: &PackedScene, p: Vec3, prim: i32) -> usize {
    let texels = crate::layout::LIGHT_TEXELS as usize;
    for (l, light) in scene.lights.iter().enumerate() {
        let found = match *light {
            Light::Point { position, .. } => prim < 0 && position == p,
            Light::Area { .. } => prim >= 0 && packed.lights[l * texels + 5][2] as i32 == prim,
            Light::Triangles { first, count, .. } => {
                (first..first + count).contains(&(prim as usize))
            }
        };
        if found {
            return l;
        }
    }
    0
}

/// Every record's differentials (frames stacked, row 0 of frame 0 first),
/// given each light's measure (`photon::differentials::light_measures`).
pub fn record_differentials(
    scene: &Scene,
    records: &[PhotonRecord],
    per_frame: usize,
    measures: &[[f32; 2]],
) -> Vec<RecordDifferentials> {
    let packed = PackedScene::new(scene);
    let mut out = vec![RecordDifferentials::default(); records.len()];
    for (i, r) in records.iter().enumerate() {
        let frame = i / per_frame;
        if frame == 0 {
            if r.incoming.w == 0.0 {
                continue;
            }
            let p = r.position.truncate();
            let l = emitting_light(scene, &packed, p, r.outgoing.w as i32);
            out[i].out = emission(r.outgoing.truncate(), measures[l]);
            continue;
        }
        if r.position.w < 0.0 {
            continue;
        }
        let prev = out[i - per_frame];
        let origin = records[i - per_frame].position.truncate();
        let d = r.incoming.truncate();
        let p = r.position.truncate();
        let prim = r.outgoing.w as usize;
        let n = primitive_normal(scene, prim, p);
        let side = if n.dot(d) < 0.0 { 1.0 } else { -1.0 };
        let nf = side * n;
        let dp = transfer(&prev.out, origin, p, d, nf);
        let mut rec = RecordDifferentials {
            axis: dp,
            diffuse_at_hit: prev.diffuse_out,
            out: Differentials::default(),
            diffuse_out: prev.diffuse_out,
            normal: nf,
        };
        if r.incoming.w == 0.0 {
            out[i] = rec;
            continue;
        }
        let shape = &scene.shapes[prim];
        let next = r.outgoing.truncate();
        let ior = match scene.materials[r.position.w as usize] {
            Material::Diffuse { albedo } => {
                rec.out = reemit(dp, albedo.max_element(), next);
                rec.diffuse_out = true;
                out[i] = rec;
                continue;
            }
            Material::Glass { ior } => ior,
            _ => 0.0,
        };
        let entering = n.dot(d) < 0.0;
        let reflected = next.dot(nf) > 0.0;
        let mut m = nf;
        if shape.normals.is_some() {
            let ms = shading_normal(shape, p, n) * side;
            let u = if reflected { 0.0 } else { 0.99999994 };
            let (again, used) = specular_shaded(d, nf, ms, ior, entering, u);
            if used && again.dot(next) > 0.9999 {
                m = ms;
            }
        }
        let dn = dp.map(|v| normal_differential(&shape.geometry, v, side));
        let dm = d.dot(m);
        let (dd, q) = if reflected || ior == 0.0 {
            let q = if ior != 0.0 {
                fresnel_dielectric(-dm, if entering { 1.0 / ior } else { ior }).0
            } else {
                1.0
            };
            (reflect(d, m, prev.out.dd, dn), q)
        } else {
            let eta = if entering { 1.0 / ior } else { ior };
            let (f, cos_t) = fresnel_dielectric(-dm, eta);
            (refract(d, m, eta, cos_t, prev.out.dd, dn), 1.0 - f)
        };
        let widen = if q > 0.0 { 1.0 / q.sqrt() } else { 1.0 };
        rec.out = Differentials {
            dp: dp.map(|v| v * widen),
            dd: dd.map(|v| v * widen),
        };
        out[i] = rec;
    }
    out
}

/// A footprint (glsl/common/footprint.glsl's records).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Footprint {
    pub p: Vec3,
    pub area: f32,
    pub a: Vec3,
    pub diffuse: bool,
    pub b: Vec3,
    pub thickness: f32,
    pub power: Vec3,
    /// The curved footprint (true) or the paper's ellipsoid.
    pub curved: bool,
}

impl Footprint {
    /// The normal semi-axis c.
    pub fn c(&self) -> Vec3 {
        self.a.cross(self.b).normalize() * self.thickness
    }

    /// The footprint's box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (a, b, c) = (self.a, self.b, self.c());
        let e = if self.curved {
            let tan_half_max = ((1.0 - COVERAGE_NORMAL_COS) / (1.0 + COVERAGE_NORMAL_COS)).sqrt();
            let depth = c.length() + tan_half_max * (a.dot(a) + b.dot(b)).sqrt();
            (a * a + b * b).map(f32::sqrt) + c.normalize().abs() * depth
        } else {
            (a * a + b * b + c * c).map(f32::sqrt)
        };
        (self.p - e, self.p + e)
    }

    /// The squared distance in the footprint of x (unit normal nq):
    /// alpha^2 + beta^2 + gamma^2 in the ellipsoid; in the curved footprint
    /// alpha^2 + beta^2, where nq is within COVERAGE_NORMAL_COS of the
    /// footprint's normal (tilted by phi) and x within |c| + rho tan(phi / 2)
    /// of its plane; above 1 outside either.
    pub fn distance2(&self, x: Vec3, nq: Vec3) -> f32 {
        let (u2, depth, tilt) = self.tests(x, nq);
        if depth >= 0.0 && tilt >= 0.0 {
            u2
        } else {
            2.0
        }
    }

    /// Whether f32 rounding may decide x the other way: one of the tests
    /// (u^2 <= 1 and, for the curved footprint, the depth and the tilt) is
    /// within `eps` (relative) of its bound and the others pass or nearly.
    pub fn on_boundary(&self, x: Vec3, nq: Vec3, eps: f32) -> bool {
        let (u2, depth, tilt) = self.tests(x, nq);
        let margins = [1.0 - u2, depth, tilt];
        margins.iter().all(|m| *m >= -eps) && margins.iter().any(|m| m.abs() < eps)
    }

    /// u^2 of x, and the curved footprint's depth and tilt tests as margins
    /// (>= 0: passed; relative to the thickness and to 1); the ellipsoid
    /// passes both by far.
    fn tests(&self, x: Vec3, nq: Vec3) -> (f32, f32, f32) {
        let (a, b, c) = (self.a, self.b, self.c());
        let e = x - self.p;
        let (bc, ca, ab) = (b.cross(c), c.cross(a), a.cross(b));
        let det = a.dot(bc);
        let u = Vec3::new(bc.dot(e), ca.dot(e), ab.dot(e)) / det;
        if !self.curved {
            return (u.dot(u), f32::INFINITY, f32::INFINITY);
        }
        let thickness = c.length();
        let cos_phi = c.dot(nq) / thickness;
        let tan_half = (1.0 - cos_phi * cos_phi).max(0.0).sqrt() / (1.0 + cos_phi);
        let rho = (u.x * a + u.y * b).length();
        let depth = (thickness + rho * tan_half - u.z.abs() * thickness) / thickness;
        (u.x * u.x + u.y * u.y, depth, cos_phi - COVERAGE_NORMAL_COS)
    }
}

/// A record's footprint (footprints.frag).
pub fn footprint(
    record: &PhotonRecord,
    diff: &RecordDifferentials,
    options: &FootprintOptions,
    delta: f32,
    power_scale: f32,
) -> Footprint {
    let semi_axis = |dp: Vec3| {
        let axis = if diff.diffuse_at_hit {
            options.smoothing * delta * dp * dp.length().powf(-0.75)
        } else {
            options.caustic_smoothing * delta * dp
        };
        let r = axis.length();
        if r > options.max_radius {
            axis * (options.max_radius / r)
        } else {
            axis
        }
    };
    let a = semi_axis(diff.axis[0]);
    let mut b = semi_axis(diff.axis[1]);
    if a.cross(b).dot(record.incoming.truncate()) > 0.0 {
        b = -b;
    }
    let mut area = std::f32::consts::PI * a.cross(b).length();
    if area.is_nan() || area <= 0.0 || area.is_infinite() {
        area = 0.0;
    }
    Footprint {
        p: record.position.truncate(),
        area,
        a,
        diffuse: diff.diffuse_at_hit,
        b,
        thickness: FOOTPRINT_THICKNESS * a.length().max(b.length()),
        power: record.power.truncate() * power_scale,
        curved: options.shape.curved(),
    }
}

/// The kernel-weighted share of the ellipse p + alpha a + beta b on the
/// surface of `material` (footprints.frag's footprint_coverage): probes at
/// a Vogel spiral's points, each passing through up to COVERAGE_CROSSINGS
/// surfaces of other materials; 1 when no probe lands.
pub fn coverage(
    scene: &Scene,
    fp: &Footprint,
    material: usize,
    samples: u32,
    epanechnikov: bool,
) -> f32 {
    if samples == 0 {
        return 1.0;
    }
    let floor = PackedScene::new(scene).offset_floor;
    let n = fp.a.cross(fp.b).normalize();
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let (mut covered, mut total) = (0.0f32, 0.0f32);
    for i in 0..samples {
        let u2 = (i as f32 + 0.5) / samples as f32;
        let phi = i as f32 * golden;
        let q = fp.p + u2.sqrt() * (phi.cos() * fp.a + phi.sin() * fp.b);
        let w = if epanechnikov { 1.0 - u2 } else { 1.0 };
        total += w;
        let h = 0.5 * q.distance(fp.p) + fp.thickness + 2.0 * offset_scale(q, floor);
        let mut o = q + n * h;
        let mut left = 2.0 * h;
        for _ in 0..COVERAGE_CROSSINGS {
            let Some((shape, t, x, normal)) = closest_hit(scene, o, -n) else {
                break;
            };
            if t > left {
                break;
            }
            if scene.shapes[shape].material == material
                && normal.dot(n).abs() >= COVERAGE_NORMAL_COS
            {
                covered += w;
                break;
            }
            let step = (o - x).dot(n) + 2.0 * offset_scale(x, floor);
            o -= n * step;
            left -= step;
        }
    }
    if covered > 0.0 {
        covered / total
    } else {
        1.0
    }
}

fn spread_bits(mut v: u32) -> u32 {
    v = v.wrapping_mul(0x0001_0001) & 0xFF00_00FF;
    v = v.wrapping_mul(0x0000_0101) & 0x0F00_F00F;
    v = v.wrapping_mul(0x0000_0011) & 0xC30C_30C3;
    v = v.wrapping_mul(0x0000_0005) & 0x4924_9249;
    v
}

/// The 30-bit Morton code of p (footprint_keys.frag).
pub fn morton(p: Vec3, lo: Vec3, scale: Vec3) -> u32 {
    let q = ((p - lo) * scale)
        .floor()
        .clamp(Vec3::ZERO, Vec3::splat(1023.0));
    (spread_bits(q.x as u32) << 2) | (spread_bits(q.y as u32) << 1) | spread_bits(q.z as u32)
}

/// Node boxes of the implicit tree over `footprints` (in order): index = node
/// (root 1; leaves from `leaves`), as footprint_leaves and footprint_reduce.
pub fn node_boxes(footprints: &[Footprint], leaf_size: u32) -> (u32, Vec<(Vec3, Vec3)>) {
    let n = footprints.len() as u32;
    let leaves = n.div_ceil(leaf_size).next_power_of_two();
    let empty = (Vec3::splat(3.0e38), Vec3::splat(-3.0e38));
    let mut boxes = vec![empty; 2 * leaves as usize];
    for j in 0..leaves {
        let first = (j * leaf_size).min(n) as usize;
        let end = ((j + 1) * leaf_size).min(n) as usize;
        let mut b = empty;
        for f in footprints[first..end].iter().filter(|f| f.area > 0.0) {
            let (lo, hi) = f.bounds();
            b = (b.0.min(lo), b.1.max(hi));
        }
        boxes[(leaves + j) as usize] = b;
    }
    for i in (1..leaves as usize).rev() {
        let (l, r) = (boxes[2 * i], boxes[2 * i + 1]);
        boxes[i] = (l.0.min(r.0), l.1.max(r.1));
    }
    (leaves, boxes)
}

/// The footprint estimate at x (normal nq) by brute force over every
/// footprint: the irradiance, and how many footprints hold x.
pub fn estimate(footprints: &[Footprint], x: Vec3, nq: Vec3, epanechnikov: bool) -> (Vec3, u32) {
    let mut sum = Vec3::ZERO;
    let mut count = 0;
    for f in footprints.iter().filter(|f| f.area > 0.0) {
        if f.c().dot(nq) <= 0.0 {
            continue;
        }
        let u2 = f.distance2(x, nq);
        if u2.is_nan() || u2 > 1.0 {
            continue;
        }
        let kernel = if epanechnikov { 2.0 * (1.0 - u2) } else { 1.0 };
        sum += f.power * (kernel / f.area);
        count += 1;
    }
    (sum, count)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Equation 13's invariant: the re-emitted differentials, carried back to
    /// the surface they leave (v along the new direction), span the incoming
    /// footprint's area widened by 1 / q; and between parallel planes the area
    /// grows as (v + t)^2 along the normal.
    #[test]
    fn reemission_keeps_the_footprint_area_and_grows_as_v_plus_t_squared() {
        let dp = [Vec3::new(0.3, 0.0, 0.1), Vec3::new(-0.05, 0.0, 0.4)];
        let q = 0.6;
        let up = Vec3::Y;
        let out = reemit(dp, q, up);
        let area_in = dp[0].cross(dp[1]).length();
        let v2 = out.dp[0].cross(out.dp[1]).length();
        assert!((v2 * q - area_in).abs() < 1e-6 * area_in, "{v2} {area_in}");
        // To a parallel plane t = 2 above, along the normal.
        let t = 2.0;
        let at = transfer(&out, Vec3::ZERO, t * up, up, -up);
        let area = at[0].cross(at[1]).length();
        let v = v2.sqrt();
        assert!((area - (v + t) * (v + t)).abs() < 1e-5 * area, "{area}");
    }

    /// A point light's emission: unit orthogonal directional differentials
    /// scaled by sqrt(directional measure), no positional ones; an area
    /// light's positional ones have the squared length of its positional measure.
    #[test]
    fn emission_scales_by_the_lights_measures() {
        let d = Vec3::new(0.2, -0.9, 0.3).normalize();
        let point = emission(d, [0.25, 0.0]);
        assert_eq!(point.dp, [Vec3::ZERO; 2]);
        for k in 0..2 {
            assert!((point.dd[k].length() - 0.5).abs() < 1e-6 && point.dd[k].dot(d).abs() < 1e-6);
        }
        let area = emission(d, [1.0, 4.0]);
        assert!((area.dp[0].cross(area.dp[1]).length() - 4.0).abs() < 1e-5);
    }

    /// A footprint at the origin facing +y (a x b = +y), semi-axes 1 and
    /// 0.7, curved or the paper's ellipsoid.
    fn footprint_at_origin(curved: bool) -> Footprint {
        let (a, b) = (Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.7, 0.0, 0.0));
        Footprint {
            p: Vec3::ZERO,
            area: std::f32::consts::PI * 0.7,
            a,
            diffuse: true,
            b,
            thickness: FOOTPRINT_THICKNESS,
            power: Vec3::ONE,
            curved,
        }
    }

    /// On balls of radius 1.2 tangent to the footprint's plane at its centre,
    /// convex and concave, every point under the ellipse whose normal tilts
    /// by less than 60 degrees is held by the curved footprint and lies in
    /// its box; the paper's ellipsoid lets many of them out. The wall across
    /// a corner, 0.3 from the centre, is held by neither.
    #[test]
    fn the_curved_footprint_holds_a_ball_and_its_box_holds_what_it_holds() {
        let (curved, ellipsoid) = (footprint_at_origin(true), footprint_at_origin(false));
        let (lo, hi) = curved.bounds();
        let radius = 1.2;
        let (mut points, mut ellipsoid_held) = (0, 0);
        for side in [-1.0f32, 1.0] {
            let centre = Vec3::new(0.0, side * radius, 0.0);
            for i in 0..60 {
                let phi = (i as f32 + 0.5).to_radians();
                for j in 0..72 {
                    let theta = (j as f32 * 5.0).to_radians();
                    let d = Vec3::new(
                        phi.sin() * theta.cos(),
                        -side * phi.cos(),
                        phi.sin() * theta.sin(),
                    );
                    let x = centre + radius * d;
                    // Under the ellipse: (z / 1)^2 + (x / 0.7)^2 <= 1.
                    if x.z * x.z + (x.x / 0.7).powi(2) > 1.0 {
                        continue;
                    }
                    // Its normal on the side the photon came from (+y).
                    let nq = -side * d;
                    points += 1;
                    assert!(curved.distance2(x, nq) <= 1.0, "{x} {nq}");
                    assert!(
                        x.cmpge(lo).all() && x.cmple(hi).all(),
                        "{x} outside {lo} {hi}"
                    );
                    ellipsoid_held += usize::from(ellipsoid.distance2(x, nq) <= 1.0);
                }
            }
        }
        assert!(points > 1000, "{points}");
        assert!(ellipsoid_held * 2 < points, "{ellipsoid_held} of {points}");
        for y in [0.01f32, 0.05, 0.2] {
            let x = Vec3::new(0.3, y, 0.1);
            assert!(curved.distance2(x, -Vec3::X) > 1.0);
            assert!(ellipsoid.distance2(x, -Vec3::X) > 1.0 || ellipsoid.c().dot(-Vec3::X) <= 0.0);
        }
    }
}
