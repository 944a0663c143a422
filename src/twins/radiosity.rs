//! Twins of progressive radiosity's passes (glsl/radiosity/): a tile's
//! sub-element shooters from the element atlas (shooters.frag), the energy an
//! element receives by the polygon or the oriented-disc form factor
//! (shoot.frag, form_factor.glsl), with visibility given by the caller
//! (shadow rays here, the item buffer on the GPU), and adaptive
//! subdivision's split test (discontinuity.frag).

use glam::Vec3;

use crate::layout::LUMINANCE;

/// A shooter: position, normal, area, residual radiosity and outline.
#[derive(Clone, Debug, PartialEq)]
pub struct Shooter {
    pub position: Vec3,
    pub normal: Vec3,
    pub area: f32,
    pub energy: Vec3,
    /// The sub-element's outline on the surface (empty: a disc only).
    pub outline: Vec<Vec3>,
}

/// Tile `tile`'s sub x sub shooters, from the atlas's element positions
/// (w = area), normals and residuals (each `width` texels a row), each at
/// its elements' centre weighted by residual power on a flat patch
/// (`flat`; by area where it has none) and by area on a curved one; block
/// k's outline from `outline(k)`.
pub fn sub_shooters(
    position: &[[f32; 4]],
    normal: &[[f32; 4]],
    residual: &[[f32; 4]],
    width: u32,
    (tile, res, tile_columns, sub): (u32, u32, u32, u32),
    flat: bool,
    outline: &dyn Fn(u32) -> Vec<Vec3>,
) -> Vec<Shooter> {
    let block = res / sub;
    let mut out = Vec::new();
    for k in 0..sub * sub {
        let base = (
            (tile % tile_columns) * res + (k % sub) * block,
            (tile / tile_columns) * res + (k / sub) * block,
        );
        let (mut p, mut n, mut e, mut area) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0.0);
        let (mut at_power, mut power) = (Vec3::ZERO, 0.0);
        for j in 0..block {
            for i in 0..block {
                let t = ((base.1 + j) * width + base.0 + i) as usize;
                let a = position[t][3];
                if a <= 0.0 {
                    continue;
                }
                let x = Vec3::from_slice(&position[t][..3]);
                let b = Vec3::from_slice(&residual[t][..3]);
                let w = a * b.dot(Vec3::from(LUMINANCE));
                p += a * x;
                at_power += w * x;
                n += a * Vec3::from_slice(&normal[t][..3]);
                e += a * b;
                area += a;
                power += w;
            }
        }
        if area > 0.0 {
            out.push(Shooter {
                position: if flat && power > 0.0 {
                    at_power / power
                } else {
                    p / area
                },
                normal: n.normalize(),
                area,
                energy: e / area,
                outline: outline(k),
            });
        }
    }
    out
}

/// Lambert's form factor from point x (unit normal n) to a polygon (or a
/// non-planar loop: the surface it bounds), clipped to x's upper half-space.
pub fn polygon_form_factor(x: Vec3, n: Vec3, outline: &[Vec3]) -> f32 {
    let mut clipped = Vec::with_capacity(outline.len() + 1);
    for k in 0..outline.len() {
        let a = outline[k] - x;
        let b = outline[(k + 1) % outline.len()] - x;
        let (da, db) = (a.dot(n), b.dot(n));
        if da > 0.0 {
            clipped.push(a);
        }
        if (da > 0.0) != (db > 0.0) {
            clipped.push(a + (da / (da - db)) * (b - a));
        }
    }
    if clipped.len() < 3 {
        return 0.0;
    }
    let mut sum = 0.0;
    for k in 0..clipped.len() {
        let a = clipped[k].normalize();
        let b = clipped[(k + 1) % clipped.len()].normalize();
        let axb = a.cross(b);
        let s = axb.length();
        if s > 0.0 {
            sum += s.atan2(a.dot(b)) * n.dot(axb) / s;
        }
    }
    sum.abs() / (2.0 * std::f32::consts::PI)
}

/// The radiosity element (x, normal nx) receives from shooter s, per unit
/// reflectance, if visible: B_s F, F the polygon form factor (`polygon`,
/// when it has an outline; the caller passes false for the shooter's own
/// elements, as the GPU does) or the oriented disc's
/// A_s cos_r cos_s / (pi d^2 + A_s). Nothing unless the element and
/// the shooter face each other (centre to centre).
pub fn received(s: &Shooter, x: Vec3, nx: Vec3, polygon: bool) -> Vec3 {
    let r = s.position - x;
    let d2 = r.dot(r);
    if d2 <= 0.0 {
        return Vec3::ZERO;
    }
    let r = r / d2.sqrt();
    let (cos_r, cos_s) = (nx.dot(r), -s.normal.dot(r));
    if cos_r <= 0.0 || cos_s <= 0.0 {
        return Vec3::ZERO;
    }
    if polygon && s.outline.len() >= 3 {
        return s.energy * polygon_form_factor(x, nx, &s.outline);
    }
    s.energy * (cos_r * cos_s * s.area / (std::f32::consts::PI * d2 + s.area))
}

/// The split test's count over a res x res tile of radiosity luminances
/// (None: no element): elements whose second difference along u or v
/// exceeds gradient x the three's mean + floor. Also how many elements lie
/// within 1e-4 (relative) of deciding otherwise, where f32 rounding on the
/// GPU may decide the other way.
pub fn discontinuities(values: &[Option<f32>], res: u32, gradient: f32, floor: f32) -> (u64, u64) {
    let at = |i: u32, j: u32| values[(j * res + i) as usize];
    let (mut count, mut close) = (0, 0);
    for j in 0..res {
        for i in 0..res {
            let Some(b) = at(i, j) else { continue };
            let mut uneven = false;
            let mut marginal = false;
            let mut test = |a: Option<f32>, c: Option<f32>| {
                if let (Some(a), Some(c)) = (a, c) {
                    let d = (a - 2.0 * b + c).abs();
                    let limit = gradient * (a + b + c) / 3.0 + floor;
                    uneven |= d > limit;
                    marginal |= (d - limit).abs() <= 1e-4 * limit.max(d);
                }
            };
            if i >= 1 && i + 1 < res {
                test(at(i - 1, j), at(i + 1, j));
            }
            if j >= 1 && j + 1 < res {
                test(at(i, j - 1), at(i, j + 1));
            }
            count += u64::from(uneven);
            close += u64::from(marginal);
        }
    }
    (count, close)
}

/// The twin of glsl/radiosity/gather_sum.frag: a pixel's indirect light from
/// the radiance `brought` back by each of its gather rays (batches summed),
/// over `rays` cosine-distributed rays from a first hit of `throughput` and
/// `albedo`.
pub fn gathered_sum(throughput: Vec3, albedo: Vec3, brought: &[Vec3], rays: u32) -> Vec3 {
    let sum: Vec3 = brought.iter().copied().sum();
    throughput * albedo * sum / rays as f32
}
