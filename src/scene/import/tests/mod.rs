//! The importers' tests, none of which needs a GPU: the Cornell box in
//! pbrt-v4 and Mitsuba against the OBJ one, shape for shape, with its PLY
//! mesh in every encoding (`cornell.rs`); a stack of transforms against its
//! flattened TOML (`transforms.rs`); bad files and what is refused
//! (`errors.rs`); and the fuzz replay over tests/fuzz_corpus/import/
//! (`fuzz.rs`).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::{convert_bytes, Converted, Files, Format, ImportOptions};
use crate::error::SceneError;
use crate::scene::{load_scene_str, Geometry, Light, Scene};

mod cornell;
mod errors;
mod fuzz;
mod transforms;

/// scenes/tests/import/, where the fixtures are.
fn dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/tests/import")
}

/// The disk, with some files' bytes replaced.
struct Patched(HashMap<PathBuf, Vec<u8>>);

impl Files for Patched {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        match self.0.get(path) {
            Some(b) => Ok(b.clone()),
            None => std::fs::read(path),
        }
    }
}

fn format(path: &Path) -> Format {
    super::format_of(path).expect("a .pbrt or .xml fixture")
}

/// Converts `text` as if it were the file `name` of scenes/tests/import/.
fn convert_text(name: &str, text: &str, opts: &ImportOptions) -> Result<Converted, SceneError> {
    convert_with(name, text, &Patched(HashMap::new()), opts)
}

fn convert_with(
    name: &str,
    text: &str,
    files: &dyn Files,
    opts: &ImportOptions,
) -> Result<Converted, SceneError> {
    let path = dir().join(name);
    convert_bytes(format(&path), text.as_bytes(), &path, files, opts)
}

/// `text` converted as the file `name` with the default options.
fn convert_default(name: &str, text: &str) -> Result<Converted, SceneError> {
    convert_text(name, text, &ImportOptions::default())
}

/// A fixture's text, for a test to edit.
fn fixture_text(name: &str) -> String {
    std::fs::read_to_string(dir().join(name)).unwrap()
}

/// `text` converted as the file `name` with the default options, and loaded;
/// with the TOML it converted to.
fn convert_and_load(name: &str, text: &str) -> (String, Scene) {
    let c = convert_default(name, text).unwrap();
    let s = load_scene_str(&c.toml, Path::new("t")).unwrap();
    (c.toml, s)
}

/// A fixture converted and loaded.
fn load(name: &str) -> Scene {
    let text = fixture_text(name);
    let c = convert_default(name, &text).unwrap_or_else(|e| panic!("{e}"));
    load_scene_str(&c.toml, Path::new(name)).unwrap_or_else(|e| panic!("{e}\n{}", c.toml))
}

/// A point in the world (the file's frame), from the scene's local frame.
fn world(s: &Scene, p: Vec3) -> [f64; 3] {
    (s.origin + p.as_dvec3()).to_array()
}

fn close(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// Corners of a parallelogram, sorted, in the world.
fn corners(s: &Scene, corner: Vec3, e1: Vec3, e2: Vec3) -> Vec<[f64; 3]> {
    let mut c: Vec<[f64; 3]> = [corner, corner + e1, corner + e2, corner + e1 + e2]
        .iter()
        .map(|&p| world(s, p))
        .collect();
    c.sort_by(|a, b| a.partial_cmp(b).unwrap());
    c
}

/// A geometry's points in the world, in an order that does not depend on
/// how the shape was written down (a triangle's or parallelogram's corners
/// sorted), and its sizes.
fn key(s: &Scene, g: &Geometry) -> (Vec<[f64; 3]>, Vec<f64>) {
    match *g {
        Geometry::Sphere { center, radius } => (vec![world(s, center)], vec![radius as f64]),
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => (
            vec![world(s, base), axis.as_dvec3().to_array()],
            vec![radius as f64, height as f64],
        ),
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => (corners(s, corner, edge1, edge2), vec![]),
        Geometry::Triangle { v0, v1, v2 } => {
            let mut v = vec![world(s, v0), world(s, v1), world(s, v2)];
            v.sort_by(|a, b| a.partial_cmp(b).unwrap());
            (v, vec![])
        }
    }
}

fn light_power(s: &Scene) -> Vec<[f64; 3]> {
    s.lights
        .iter()
        .map(|l| l.power(&s.shapes).as_dvec3().to_array())
        .collect()
}

/// Every light's emitting direction (None for a point light): the Area's
/// normal, or a Triangles light's winding normal.
fn light_normals(s: &Scene) -> Vec<Option<[f64; 3]>> {
    s.lights
        .iter()
        .map(|l| match *l {
            Light::Area { normal, .. } => Some(normal.as_dvec3().to_array()),
            Light::Point { .. } => None,
            Light::Triangles { first, .. } => match s.shapes[first].geometry {
                Geometry::Triangle { v0, v1, v2 } => {
                    Some((v1 - v0).cross(v2 - v0).normalize().as_dvec3().to_array())
                }
                _ => None,
            },
        })
        .collect()
}
