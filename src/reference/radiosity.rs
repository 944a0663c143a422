//! Twins of progressive radiosity's shooting (glsl/radiosity/shooters.frag
//! and shoot.frag): a patch's sub-element shooters from the element atlas,
//! and the oriented-disc form factor, with visibility given by the caller
//! (shadow rays here, the item buffer on the GPU).

use glam::Vec3;

/// A shooter: position, normal, area and residual radiosity.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shooter {
    pub position: Vec3,
    pub normal: Vec3,
    pub area: f32,
    pub energy: Vec3,
}

/// Patch `patch`'s sub x sub shooters, from the atlas's element positions
/// (w = area), normals and residuals (each `width` texels a row).
pub fn sub_shooters(
    position: &[[f32; 4]],
    normal: &[[f32; 4]],
    residual: &[[f32; 4]],
    width: u32,
    (patch, res, tile_columns, sub): (u32, u32, u32, u32),
) -> Vec<Shooter> {
    let block = res / sub;
    let mut out = Vec::new();
    for k in 0..sub * sub {
        let base = (
            (patch % tile_columns) * res + (k % sub) * block,
            (patch / tile_columns) * res + (k / sub) * block,
        );
        let (mut p, mut n, mut e, mut area) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, 0.0);
        for j in 0..block {
            for i in 0..block {
                let t = ((base.1 + j) * width + base.0 + i) as usize;
                let a = position[t][3];
                if a <= 0.0 {
                    continue;
                }
                p += a * Vec3::from_slice(&position[t][..3]);
                n += a * Vec3::from_slice(&normal[t][..3]);
                e += a * Vec3::from_slice(&residual[t][..3]);
                area += a;
            }
        }
        if area > 0.0 {
            out.push(Shooter {
                position: p / area,
                normal: n.normalize(),
                area,
                energy: e / area,
            });
        }
    }
    out
}

/// The radiosity element (x, normal nx) receives from shooter s, per unit
/// reflectance, if visible: B_s A_s max(cos_r cos_s, 0) / (pi d^2 + A_s).
pub fn received(s: &Shooter, x: Vec3, nx: Vec3) -> Vec3 {
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
    s.energy * (cos_r * cos_s * s.area / (std::f32::consts::PI * d2 + s.area))
}
