//! Procedural meshes, so benchmarks and tests need no mesh files in the tree:
//! a displaced sphere and a torus knot, both closed with shared vertices (so
//! a watertight intersection test lets no ray through them).

use glam::Vec3;

use super::{Geometry, Shape};

/// Positions and triangles by index: a vertex shared by triangles is one
/// value, so each of them reads the same bits.
#[derive(Clone, Debug, Default)]
pub struct IndexedMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl IndexedMesh {
    /// One triangle shape each, of `material`, after `p * scale + translate`.
    pub fn shapes(&self, material: usize, scale: f32, translate: Vec3) -> Vec<Shape> {
        let p: Vec<Vec3> = self
            .positions
            .iter()
            .map(|&p| p * scale + translate)
            .collect();
        self.triangles
            .iter()
            .map(|t| {
                let geometry = Geometry::Triangle {
                    v0: p[t[0] as usize],
                    v1: p[t[1] as usize],
                    v2: p[t[2] as usize],
                };
                Shape::new(geometry, material)
            })
            .collect()
    }

    /// The mesh as OBJ text (`v` lines, then `f` lines), with a `vn` per
    /// vertex when `normals` are given (one per position, in order).
    pub fn obj_text(&self, normals: Option<&[Vec3]>) -> String {
        let mut out = String::new();
        for p in &self.positions {
            out += &format!("v {:?} {:?} {:?}\n", p.x, p.y, p.z);
        }
        for n in normals.unwrap_or(&[]) {
            out += &format!("vn {:?} {:?} {:?}\n", n.x, n.y, n.z);
        }
        for t in &self.triangles {
            let [a, b, c] = t.map(|i| i + 1);
            out += &match normals {
                Some(_) => format!("f {a}//{a} {b}//{b} {c}//{c}\n"),
                None => format!("f {a} {b} {c}\n"),
            };
        }
        out
    }

    /// Each vertex's direction from the origin: a sphere's normals.
    pub fn radial_normals(&self) -> Vec<Vec3> {
        self.positions
            .iter()
            .map(|p| p.normalize_or_zero())
            .collect()
    }

    /// Triangles of a grid of `rows` x `columns` vertices that wraps around in
    /// columns (and in rows too when `wrap_rows`), offset by `first`.
    fn grid(&mut self, first: u32, rows: u32, columns: u32, wrap_rows: bool) {
        let at = |r: u32, c: u32| first + (r % rows) * columns + c % columns;
        let strips = if wrap_rows { rows } else { rows - 1 };
        for r in 0..strips {
            for c in 0..columns {
                let (a, b, d, e) = (at(r, c), at(r, c + 1), at(r + 1, c), at(r + 1, c + 1));
                self.triangles.push([a, d, b]);
                self.triangles.push([b, d, e]);
            }
        }
    }
}

/// A unit sphere of about `triangles` triangles (at least 8) whose radius is
/// displaced by up to 10% by smooth bumps: closed, outward winding.
pub fn displaced_sphere(triangles: usize) -> IndexedMesh {
    uv_sphere(triangles, 0.05)
}

/// A unit UV sphere of about `triangles` triangles (at least 8), its radius
/// displaced by smooth bumps of up to 2 `bumps` (0: a plain sphere, whose
/// vertices lie on the unit sphere): closed, outward winding.
pub fn uv_sphere(triangles: usize, bumps: f32) -> IndexedMesh {
    // Rings r and 2r columns give 4r(r - 1) triangles.
    let rings = ((triangles as f64 / 4.0).sqrt().round() as u32).max(2);
    let columns = 2 * rings;
    let bump = |d: Vec3| 1.0 + bumps * ((7.0 * d.x).sin() * (5.0 * d.y).sin() + (6.0 * d.z).cos());
    let point = |theta: f32, phi: f32| {
        let d = Vec3::new(
            theta.sin() * phi.cos(),
            theta.cos(),
            theta.sin() * phi.sin(),
        );
        d * bump(d)
    };
    let mut m = IndexedMesh::default();
    m.positions.push(point(0.0, 0.0));
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for c in 0..columns {
            let phi = std::f32::consts::TAU * c as f32 / columns as f32;
            m.positions.push(point(theta, -phi));
        }
    }
    m.positions.push(point(std::f32::consts::PI, 0.0));
    let south = m.positions.len() as u32 - 1;
    for c in 0..columns {
        let next = (c + 1) % columns;
        m.triangles.push([0, 1 + c, 1 + next]);
        let last = 1 + (rings - 2) * columns;
        m.triangles.push([south, last + next, last + c]);
    }
    m.grid(1, rings - 1, columns, false);
    m
}

/// A (2, 3) torus knot tube of about `triangles` triangles (at least 144),
/// about 3 across: closed, outward winding.
pub fn torus_knot(triangles: usize) -> IndexedMesh {
    // `along` rings of `around` vertices, along = 8 around: 16 around^2 triangles.
    let around = ((triangles as f64 / 16.0).sqrt().round() as u32).max(3);
    let along = 8 * around;
    let curve = |t: f32| {
        let (p, q) = (2.0 * t, 3.0 * t);
        Vec3::new(
            (2.0 + q.cos()) * p.cos(),
            (2.0 + q.cos()) * p.sin(),
            q.sin(),
        ) * 0.5
    };
    let mut m = IndexedMesh::default();
    for i in 0..along {
        let t = std::f32::consts::TAU * i as f32 / along as f32;
        let c = curve(t);
        let tangent = (curve(t + 1e-3) - curve(t - 1e-3)).normalize();
        let binormal = tangent.cross(c).normalize();
        let normal = binormal.cross(tangent);
        for j in 0..around {
            let a = -std::f32::consts::TAU * j as f32 / around as f32;
            m.positions
                .push(c + 0.15 * (a.cos() * normal + a.sin() * binormal));
        }
    }
    m.grid(0, along, around, true);
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    /// Closed and consistently wound: every directed edge appears once, and
    /// its reverse once.
    fn assert_closed(m: &IndexedMesh) {
        let mut edges = HashMap::new();
        for t in &m.triangles {
            for k in 0..3 {
                *edges.entry((t[k], t[(k + 1) % 3])).or_insert(0) += 1;
            }
        }
        for (&(a, b), &n) in &edges {
            assert_eq!(n, 1, "edge {a}-{b} used {n} times");
            assert_eq!(edges.get(&(b, a)), Some(&1), "edge {a}-{b} has no twin");
        }
    }

    /// Outward: the signed volume is positive.
    fn volume(m: &IndexedMesh) -> f32 {
        m.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| m.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn generated_meshes_are_closed_outward_and_near_the_asked_size() {
        for n in [8, 1000, 100_000] {
            let s = displaced_sphere(n);
            assert_closed(&s);
            // A coarse sphere is a polytope inside the unit ball; a fine one nears 4.19.
            let low = if n < 1000 { 1.0 } else { 3.5 };
            assert!(volume(&s) > low && volume(&s) < 5.0, "{}", volume(&s));
            let got = s.triangles.len() as f64;
            assert!((got / n as f64 - 1.0).abs() < 0.5, "{n}: {got}");
        }
        for n in [144, 1000, 100_000] {
            let k = torus_knot(n);
            assert_closed(&k);
            assert!(volume(&k) > 0.0);
            let got = k.triangles.len() as f64;
            assert!((got / n as f64 - 1.0).abs() < 0.5, "{n}: {got}");
        }
    }
}
