//! TOML scene files (format in docs/src/guide/scene-format.md) into `Scene`, with every error
//! naming the file, line and field.
//!
//! The text is parsed with toml's span-keeping document API (`DeTable`), in
//! which every key and value keeps its byte span. Overrides (`key.path=value`,
//! see `load_scene_str_with_overrides`; `overrides.rs`) are spliced into that
//! document before anything is read, so they are validated exactly like the
//! file. Then each section is read by its own function (`sections.rs`:
//! camera, render, photon_map, materials, shapes, lights; `mesh.rs`: mesh
//! shapes) through `Table` (`table.rs`), which takes every error's place from
//! the span of what it is about (`context.rs` turns a span into the file or
//! override, and the line, it came from):
//!
//! - an unknown field: the unknown key's line;
//! - a missing field: the table's header line (or the inline table's line);
//! - a wrong type: the value's line (the element's, inside an array);
//! - an unknown `type`: the `type = ...` line;
//! - a value out of range: the value's line, or the table's header line when
//!   the value is a default (`defaults`) that does not fit.
//!
//! Errors about the shape of the document (unknown, missing, mistyped fields,
//! unknown types) name the key as written in `field` and the full path in
//! their message; validation errors name the full path (`shape[6].radius`).
//!
//! Points are read in f64 and rebased (`rebase`): before the sections are
//! read, a pre-pass over the document (here) finds the scene's local origin
//! O (the centre of its points' box, or the camera), and every point p is
//! then stored as the f32 of p - O. Directions, edges, radii and colours are
//! read as f32, as before. `load_scene_str_translated` moves every point by
//! a vector in f64 first: a file whose coordinates are moved, without its
//! text being edited.

use std::path::Path;

use glam::DVec3;
use serde::Deserialize;
use toml::de::{DeTable, DeValue};
use toml::Spanned;

use super::defaults::MAX_COORDINATE;
pub use super::defaults::{
    MAX_GRID_SIDE, MAX_IMAGE_SIDE, MAX_K, MAX_PHOTONS_STORED, MAX_SHADOW_RAYS, MAX_SPECULAR_DEPTH,
};
use super::rebase::{self, dvec3, Coord, Rebase};
use super::Scene;
use context::{Cx, Value};
use table::Strict;

mod context;
mod mesh;
mod overrides;
mod sections;
mod table;
#[cfg(test)]
mod tests;

pub use crate::error::SceneError;
pub(super) use context::line_of;

pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = super::file::read_stable(path).map_err(|e| {
        SceneError::new(
            path,
            0,
            "(file)",
            format!("cannot read the scene file: {e}"),
        )
    })?;
    load_scene_str(&text, path)
}

/// Loads a scene from TOML text; `path` names it in errors and anchors OBJ paths.
pub fn load_scene_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
    load_scene_str_with_overrides(text, path, &[])
}

/// Loads a scene from TOML text with `overrides` applied, in order, before
/// anything is validated: pairs of a key path and a TOML value, such as
/// `("photon_map.k", "64")`, `("camera.width", "256")`,
/// `("shape[1].radius", "0.5")` or
/// `("materials.gold", "{ type = \"glass\", ior = 1.5 }")`.
///
/// A path's segments are keys, each with an optional 0-based `[index]` into
/// an array of tables; missing tables on the way are created, and an index
/// one past the end appends (`light[1] = { ... }` to a scene with one
/// light). An overridden value is checked exactly like one in the file, and
/// every error about it names the override as its file, e.g.
/// `--set shape[1].radius:1: shape[1].radius: -1 must be greater than 0`.
pub fn load_scene_str_with_overrides(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
) -> Result<Scene, SceneError> {
    load_scene_document(text, path, overrides, DVec3::ZERO, Rebase::SceneCentre)
}

/// Loads a scene from TOML text as if every point in it (camera position and
/// target, centres, bases, corners, vertices, mesh placements, point lights,
/// grid bounds) were moved by `t`: each is read in f64, `t` is added in
/// f64, and the scene is rebased as `rebase` says. So "the file moved by
/// 1e6" needs no edited text (the stress suite and tests use this).
pub fn load_scene_str_translated(
    text: &str,
    path: &Path,
    t: DVec3,
    rebase: Rebase,
) -> Result<Scene, SceneError> {
    load_scene_document(text, path, &[], t, rebase)
}

/// Parses, applies the overrides, finds the local origin, reads the sections.
fn load_scene_document(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
    t: DVec3,
    rebase: Rebase,
) -> Result<Scene, SceneError> {
    let overrides = overrides::placed(text, overrides);
    let mut cx = Cx::new(text, path, overrides.iter().map(|o| o.source()).collect());
    let mut root = DeTable::parse(text)
        .map_err(|e| cx.syntax_error(&e))?
        .into_inner();
    for o in &overrides {
        o.apply(&mut root)?;
    }
    cx.translate = t;
    cx.origin = local_origin(&root, t, rebase);
    sections::read_scene(&cx, &root)
}

/// Where each section keeps its points.
const POINTS: &[(&str, &[&str])] = &[
    ("camera", &["position", "look_at"]),
    ("photon_map", &["grid_min", "grid_max"]),
    (
        "shape",
        &["center", "base", "corner", "vertices", "translate"],
    ),
    ("light", &["corner", "position"]),
];

/// The pre-pass: the local origin of the document's points, each moved by
/// `t`. It refuses nothing: whatever is not a finite point within
/// MAX_COORDINATE is left out here and refused, in its place, by the reading
/// that follows.
fn local_origin(root: &DeTable, t: DVec3, rebase: Rebase) -> DVec3 {
    let points_of = |value: &Value| -> Vec<DVec3> {
        let many = match <[Coord; 3]>::deserialize(Strict(value.clone())) {
            Ok(p) => vec![p],
            Err(_) => Vec::<[Coord; 3]>::deserialize(Strict(value.clone())).unwrap_or_default(),
        };
        many.into_iter()
            .map(|p| dvec3(p) + t)
            .filter(|p| p.is_finite() && p.abs().max_element() <= f64::from(MAX_COORDINATE))
            .collect()
    };
    let tables = |section: &str| -> Vec<&DeTable> {
        match root.get(section).map(Spanned::get_ref) {
            Some(DeValue::Table(t)) => vec![t],
            Some(DeValue::Array(items)) => items
                .iter()
                .filter_map(|i| match i.get_ref() {
                    DeValue::Table(t) => Some(t),
                    _ => None,
                })
                .collect(),
            _ => Vec::new(),
        }
    };
    let mut points = Vec::new();
    for (section, keys) in POINTS {
        for table in tables(section) {
            for key in *keys {
                points.extend(table.get(*key).map(points_of).unwrap_or_default());
            }
        }
    }
    let camera = tables("camera")
        .first()
        .and_then(|c| c.get("position"))
        .map(points_of)
        .and_then(|p| p.first().copied());
    rebase::origin(&points, camera, rebase)
}
