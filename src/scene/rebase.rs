//! Points in f64, and the local origin a scene is rebased to before anything
//! becomes f32.
//!
//! Every point of a scene file (camera position and target, sphere centres,
//! cylinder bases, corners, vertices, mesh placements, point lights, grid
//! bounds) is read as f64. The loader first finds the scene's local origin O
//! (`origin`), then stores each point p as the f32 of p - O, so a scene far
//! from the world's origin is as precise in f32 as one at it. The renderer is
//! translation-invariant, so it works in that local frame unchanged;
//! `Scene::origin` says where the frame sits in the world.

use glam::DVec3;
use serde::de::{Deserialize, Deserializer, Visitor};

/// Where a scene's local origin goes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Rebase {
    /// The centre of the box of the scene's points, rounded so that a scene
    /// around the world's origin stays where it is (see `centre_origin`).
    #[default]
    SceneCentre,
    /// The camera's position, exactly.
    Camera,
}

/// One coordinate of a point, read as f64. Its type errors say "expected
/// f32", as every other number of the format does, so the loader's messages
/// are the same whatever precision a field is read in.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Coord(pub f64);

impl<'de> Deserialize<'de> for Coord {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Number;
        impl Visitor<'_> for Number {
            type Value = Coord;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("f32")
            }
            fn visit_f64<E>(self, v: f64) -> Result<Coord, E> {
                Ok(Coord(v))
            }
            fn visit_i64<E>(self, v: i64) -> Result<Coord, E> {
                Ok(Coord(v as f64))
            }
            fn visit_u64<E>(self, v: u64) -> Result<Coord, E> {
                Ok(Coord(v as f64))
            }
        }
        d.deserialize_f64(Number)
    }
}

/// A point of three coordinates as a `DVec3`.
pub fn dvec3(p: [Coord; 3]) -> DVec3 {
    DVec3::new(p[0].0, p[1].0, p[2].0)
}

/// The local origin of a scene whose points (already in the world frame)
/// are `points` and whose camera stands at `camera`.
pub fn origin(points: &[DVec3], camera: Option<DVec3>, rebase: Rebase) -> DVec3 {
    match (rebase, camera) {
        (Rebase::Camera, Some(c)) => c,
        _ => centre_origin(points),
    }
}

/// The centre of the points' box, rounded on each axis to a multiple of q,
/// the power of two at or above the box's longest side (ties to even).
///
/// - A box that contains the world's origin gives O = 0 (its centre is
///   within q/2 of it), so a scene around the origin loads bit for bit as it
///   did before rebasing existed.
/// - p - O is exact in f64 when O = 0 or |p| >= q (O is a multiple of q and
///   |p - O| <= q, so the difference is a multiple of the finer of q and p's
///   own spacing that fits in 53 bits), and otherwise off by at most half
///   f64's spacing at q. The rounding that matters is the conversion to f32,
///   which a copy of the scene moved by a multiple of q shares with the
///   original: the moved file loads as the original did.
/// - No point is further than 1.5 times the box's longest side from O.
///
/// No points (a document the loader will refuse anyway): the world's origin.
pub fn centre_origin(points: &[DVec3]) -> DVec3 {
    let Some(first) = points.first() else {
        return DVec3::ZERO;
    };
    let (lo, hi) = points
        .iter()
        .fold((*first, *first), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = lo * 0.5 + hi * 0.5;
    let side = (hi - lo).max_element();
    if !(side > 0.0 && side.is_finite()) {
        return centre;
    }
    let q = 2f64.powi(side.log2().ceil() as i32);
    let round = |c: f64| (c / q).round_ties_even() * q;
    DVec3::new(round(centre.x), round(centre.y), round(centre.z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_around_the_origin_keeps_it() {
        let pts = [DVec3::new(-3.0, -0.01, -3.2), DVec3::new(3.0, 3.2, 3.2)];
        assert_eq!(centre_origin(&pts), DVec3::ZERO);
        // One side at 0 and a side of exactly q: a tie, to even (0).
        let pts = [DVec3::ZERO, DVec3::new(4.0, 4.0, 4.0)];
        assert_eq!(centre_origin(&pts), DVec3::ZERO);
    }

    #[test]
    fn a_moved_box_is_moved_back_by_a_multiple_of_q() {
        let t = DVec3::new(1e6, -1e6, 1e6);
        let pts = [
            DVec3::new(-3.0, -0.01, -3.2) + t,
            DVec3::new(3.0, 3.2, 3.2) + t,
        ];
        assert_eq!(centre_origin(&pts), t);
        // Side 0.6, so q = 1: the centre 10.6 rounds to 11.
        let o = centre_origin(&[DVec3::splat(10.3), DVec3::splat(10.9)]);
        assert_eq!(o, DVec3::splat(11.0));
    }

    #[test]
    fn camera_rebasing_takes_the_camera_exactly() {
        let c = DVec3::new(1e6 + 0.1, 3.2, -7.0);
        assert_eq!(origin(&[DVec3::ZERO], Some(c), Rebase::Camera), c);
        assert_eq!(origin(&[], None, Rebase::Camera), DVec3::ZERO);
    }
}
