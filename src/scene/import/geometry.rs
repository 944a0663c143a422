//! Geometry the importers share: transforms, triangle meshes placed in the
//! world, emitting meshes turned into parallelogram lights, and the
//! tessellation of shapes photonmap has no primitive for (discs, cubes).

use glam::{DMat4, DVec3, DVec4};

use super::model::{Emitter, Model, Surface};

/// An indexed triangle mesh in its object space.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    pub positions: Vec<DVec3>,
    /// One per position, where the file has them.
    pub normals: Option<Vec<DVec3>>,
    /// One per position, where the file has them (read, not rendered:
    /// photonmap has no textures).
    pub uv: Option<Vec<[f64; 2]>>,
    pub triangles: Vec<[usize; 3]>,
}

impl Mesh {
    /// Checks every index against the positions.
    pub fn check(&self) -> Result<(), String> {
        let n = self.positions.len();
        for (i, t) in self.triangles.iter().enumerate() {
            if let Some(bad) = t.iter().find(|&&v| v >= n) {
                return Err(format!(
                    "triangle {i} names vertex {bad}, but there are {n} vertices"
                ));
            }
        }
        for (what, len) in [
            ("normals", self.normals.as_ref().map(Vec::len)),
            ("uv", self.uv.as_ref().map(Vec::len)),
        ] {
            if let Some(len) = len.filter(|&l| l != n) {
                return Err(format!("{len} {what} for {n} vertices"));
            }
        }
        Ok(())
    }
}

/// A placement: object space to world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Xf(pub DMat4);

impl Xf {
    pub const IDENTITY: Xf = Xf(DMat4::IDENTITY);

    pub fn point(&self, p: DVec3) -> DVec3 {
        let h = self.0 * DVec4::new(p.x, p.y, p.z, 1.0);
        if h.w != 0.0 && h.w != 1.0 {
            h.truncate() / h.w
        } else {
            h.truncate()
        }
    }

    pub fn vector(&self, v: DVec3) -> DVec3 {
        self.0.transform_vector3(v)
    }

    pub fn normal(&self, n: DVec3) -> DVec3 {
        self.0.inverse().transpose().transform_vector3(n)
    }

    /// Whether it turns right-handed frames left-handed.
    pub fn swaps_handedness(&self) -> bool {
        glam::DMat3::from_mat4(self.0).determinant() < 0.0
    }

    /// The uniform scale of a rotation-and-uniform-scale (plus move), or
    /// None when it shears or scales the axes differently.
    pub fn uniform_scale(&self) -> Option<f64> {
        let m = glam::DMat3::from_mat4(self.0);
        let cols = [m.x_axis, m.y_axis, m.z_axis];
        let s = cols[0].length();
        let ok = s > 0.0
            && cols.iter().all(|c| (c.length() - s).abs() <= 1e-6 * s)
            && cols[0].dot(cols[1]).abs() <= 1e-6 * s * s
            && cols[0].dot(cols[2]).abs() <= 1e-6 * s * s
            && cols[1].dot(cols[2]).abs() <= 1e-6 * s * s;
        ok.then_some(s)
    }
}

/// How an emitting shape emits: radiance, the side (`flip`: opposite to the
/// triangles' winding normal), and whether the file asked for both sides.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Emission {
    pub radiance: [f64; 3],
    pub flip: bool,
    /// pbrt: with vertex normals, the emitting side follows them (flipped
    /// by `flip_normals`), not the winding.
    pub follow_normals: bool,
    pub flip_normals: bool,
}

/// Places a mesh in the world: as triangles of `material`, or, emitting, as
/// parallelogram lights (each pair of triangles that makes one). Returns the
/// triangles that emit but pair with none (the caller refuses them, or
/// keeps them as surfaces without emission under --lenient).
pub fn place_mesh(
    model: &mut Model,
    mesh: &Mesh,
    xf: &Xf,
    material: usize,
    emission: Option<Emission>,
) -> usize {
    let world: Vec<DVec3> = mesh.positions.iter().map(|&p| xf.point(p)).collect();
    let tri = |t: &[usize; 3]| [world[t[0]], world[t[1]], world[t[2]]];
    let Some(e) = emission else {
        for t in &mesh.triangles {
            model.triangle(tri(t), material);
        }
        return 0;
    };
    let side = |t: &[usize; 3]| {
        let v = tri(t);
        let n = (v[1] - v[0]).cross(v[2] - v[0]);
        match (&mesh.normals, e.follow_normals) {
            (Some(ns), true) => {
                let s = t.iter().map(|&i| xf.normal(ns[i])).sum::<DVec3>();
                let s = if e.flip_normals { -s } else { s };
                if n.dot(s) < 0.0 {
                    -n
                } else {
                    n
                }
            }
            _ if e.flip => -n,
            _ => n,
        }
    };
    let mut unpaired = 0;
    let mut i = 0;
    while i < mesh.triangles.len() {
        let a = &mesh.triangles[i];
        let pair = mesh
            .triangles
            .get(i + 1)
            .and_then(|b| parallelogram(tri(a), tri(b)).map(|q| (q, b)));
        match pair {
            Some(((corner, edge1, edge2), b)) if side(a).dot(side(b)) > 0.0 => {
                let normal = side(a).normalize();
                model.emitters.push(Emitter::Area {
                    corner,
                    edge1,
                    edge2,
                    normal,
                    radiance: e.radiance,
                });
                i += 2;
            }
            _ => {
                model.triangle(tri(a), material);
                unpaired += 1;
                i += 1;
            }
        }
    }
    unpaired
}

/// The parallelogram two triangles make, sharing an edge: (corner, edge1,
/// edge2), or None.
pub fn parallelogram(a: [DVec3; 3], b: [DVec3; 3]) -> Option<(DVec3, DVec3, DVec3)> {
    let size = (a[1] - a[0]).length().max((a[2] - a[0]).length());
    let eq = |p: DVec3, q: DVec3| (p - q).length() <= 1e-9 * size.max(1e-300);
    let shared: Vec<DVec3> = a
        .iter()
        .copied()
        .filter(|&p| b.iter().any(|&q| eq(p, q)))
        .collect();
    if shared.len() != 2 {
        return None;
    }
    let own_a = *a.iter().find(|&&p| !shared.iter().any(|&s| eq(p, s)))?;
    let own_b = *b.iter().find(|&&p| !shared.iter().any(|&s| eq(p, s)))?;
    let (s1, s2) = (shared[0], shared[1]);
    let fourth = s1 + s2 - own_a;
    if (fourth - own_b).length() > 1e-6 * size {
        return None;
    }
    let (edge1, edge2) = (s1 - own_a, s2 - own_a);
    (edge1.cross(edge2).length() > 1e-9 * size * size).then_some((own_a, edge1, edge2))
}

/// The segments discs and cylinders' caps are cut into.
pub const DISC_SEGMENTS: usize = 64;

/// A disc (or annulus from `inner`) of `radius` in the plane z = `height`,
/// facing +z, over `phi_max` radians: a triangle mesh.
pub fn disc(radius: f64, inner: f64, height: f64, phi_max: f64) -> Mesh {
    let n = ((DISC_SEGMENTS as f64 * phi_max / std::f64::consts::TAU).ceil() as usize).max(1);
    let mut m = Mesh::default();
    let at = |r: f64, i: usize| {
        let phi = phi_max * i as f64 / n as f64;
        DVec3::new(r * phi.cos(), r * phi.sin(), height)
    };
    for i in 0..=n {
        m.positions.push(at(radius, i));
        m.positions.push(at(inner, i));
    }
    for i in 0..n {
        let (o0, i0, o1, i1) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        m.triangles.push([o0, o1, i1]);
        if inner > 0.0 {
            m.triangles.push([o0, i1, i0]);
        }
    }
    m
}

/// The open cylinder of pbrt and Mitsuba (radius, from z0 to z1 along z)
/// placed by `xf`: photonmap's cylinder when `xf` keeps shapes, else a
/// triangle mesh.
pub fn cylinder(radius: f64, z0: f64, z1: f64, xf: &Xf) -> Result<Surface, Mesh> {
    let (lo, hi) = (z0.min(z1), z0.max(z1));
    if let Some(s) = xf.uniform_scale() {
        let base = xf.point(DVec3::new(0.0, 0.0, lo));
        let top = xf.point(DVec3::new(0.0, 0.0, hi));
        let axis = (top - base).normalize();
        return Ok(Surface::Cylinder {
            base,
            axis,
            radius: radius * s,
            height: (top - base).length(),
        });
    }
    let n = DISC_SEGMENTS;
    let mut m = Mesh::default();
    for i in 0..=n {
        let phi = std::f64::consts::TAU * i as f64 / n as f64;
        let (x, y) = (radius * phi.cos(), radius * phi.sin());
        m.positions.push(DVec3::new(x, y, lo));
        m.positions.push(DVec3::new(x, y, hi));
    }
    for i in 0..n {
        let (a, b, c, d) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
        m.triangles.push([a, c, d]);
        m.triangles.push([a, d, b]);
    }
    Err(m)
}

/// Mitsuba's rectangle: [-1, 1]^2 at z = 0, facing +z.
pub fn rectangle() -> Mesh {
    Mesh {
        positions: vec![
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(-1.0, 1.0, 0.0),
        ],
        triangles: vec![[0, 1, 2], [0, 2, 3]],
        ..Mesh::default()
    }
}

/// Mitsuba's cube: [-1, 1]^3, faces outward.
pub fn cube() -> Mesh {
    let mut m = Mesh::default();
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let n = DVec3::from_array(std::array::from_fn(|i| if i == axis { sign } else { 0.0 }));
            let u = DVec3::from_array(std::array::from_fn(|i| {
                if i == (axis + 1) % 3 {
                    1.0
                } else {
                    0.0
                }
            }));
            let v = n.cross(u);
            let base = m.positions.len();
            for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                m.positions.push(n + a * u + b * v);
            }
            m.triangles.push([base, base + 1, base + 2]);
            m.triangles.push([base, base + 2, base + 3]);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_triangles_of_a_quad_make_its_parallelogram() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let (c, e1, e2) = parallelogram([p[0], p[1], p[2]], [p[0], p[2], p[3]]).unwrap();
        assert!((e1.cross(e2).length() - 1.0).abs() < 1e-12, "{c} {e1} {e2}");
        let kite = [DVec3::ZERO, DVec3::X, DVec3::new(2.0, 2.0, 0.0)];
        assert!(parallelogram([p[0], p[1], p[2]], kite).is_none());
    }

    #[test]
    fn cube_faces_point_outwards_and_discs_cover_their_area() {
        let c = cube();
        for t in &c.triangles {
            let [a, b, d] = t.map(|i| c.positions[i]);
            let n = (b - a).cross(d - a);
            assert!(n.dot(a + b + d) > 0.0, "{t:?}");
        }
        let d = disc(1.0, 0.0, 0.0, std::f64::consts::TAU);
        let area: f64 = d
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| d.positions[i]);
                0.5 * (b - a).cross(c - a).z
            })
            .sum();
        assert!((area - std::f64::consts::PI).abs() < 0.01, "{area}");
    }
}
