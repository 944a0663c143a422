//! Camera paths for fly-throughs on one photon map (`render --camera-path`):
//! key cameras in TOML, optionally interpolated to a number of frames.
//!
//! ```toml
//! frames = 24                 # optional: this many frames, linear between keys
//! [[key]]
//! position = [0.0, 2.0, 5.5]
//! look_at = [0.0, 0.6, 0.0]
//! vfov = 38.0                 # optional: the scene's
//! ```
//!
//! Key positions are in the scene file's frame: they are read in f64 and
//! rebased to the scene's local origin (`Scene::origin`) like the scene's
//! own points.

use std::path::Path;

use glam::DVec3;
use serde::Deserialize;

use super::rebase::{dvec3, Coord};
use super::{Camera, SceneError};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathFile {
    frames: Option<i64>,
    key: Vec<Key>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Key {
    position: [Coord; 3],
    look_at: [Coord; 3],
    vfov: Option<f32>,
}

/// The cameras of a path, each like `base` (size, up) but placed as the path
/// says, in the frame of a scene whose local origin is `origin`.
pub fn load_camera_path(
    path: &Path,
    base: &Camera,
    origin: DVec3,
) -> Result<Vec<Camera>, SceneError> {
    let text = super::file::read_stable(path).map_err(|e| {
        SceneError::new(
            path,
            0,
            "(file)",
            format!("cannot read the camera path: {e}"),
        )
    })?;
    camera_path_from_str(&text, path, base, origin)
}

/// `load_camera_path` on the file's text; `path` names it in errors.
pub fn camera_path_from_str(
    text: &str,
    path: &Path,
    base: &Camera,
    origin: DVec3,
) -> Result<Vec<Camera>, SceneError> {
    let err = |line, field: &str, message| SceneError::new(path, line, field, message);
    let file: PathFile = toml::from_str(text).map_err(|e| {
        let line = e.span().map_or(0, |s| super::load::line_of(text, s.start));
        err(line, "(camera path)", e.message().to_string())
    })?;
    if file.key.is_empty() {
        return Err(err(
            1,
            "key",
            "a camera path needs at least one [[key]]".into(),
        ));
    }
    let mut keys = Vec::new();
    for (i, k) in file.key.iter().enumerate() {
        let (p, l) = (dvec3(k.position), dvec3(k.look_at));
        let vfov = k.vfov.unwrap_or(base.vfov_degrees);
        let (p, l) = ((p - origin).as_vec3(), (l - origin).as_vec3());
        if !p.is_finite() || !l.is_finite() || (p - l).length() == 0.0 {
            return Err(err(
                0,
                &format!("key[{i}]"),
                "position and look_at must be finite and distinct".into(),
            ));
        }
        if (l - p).normalize().cross(base.up).length() < 1e-6 {
            return Err(err(
                0,
                &format!("key[{i}]"),
                format!(
                    "looks along the scene camera's up vector {:?}: no image plane is defined",
                    base.up.to_array()
                ),
            ));
        }
        if !(vfov > 0.0 && vfov < 180.0) {
            return Err(err(
                0,
                &format!("key[{i}].vfov"),
                format!("{vfov} is outside the allowed range (0, 180)"),
            ));
        }
        keys.push((p, l, vfov));
    }
    let frames = match file.frames {
        None => keys.len(),
        Some(n) if (1..=100_000).contains(&n) => n as usize,
        Some(n) => {
            return Err(err(
                1,
                "frames",
                format!("{n} is outside the allowed range 1..=100000"),
            ))
        }
    };
    Ok((0..frames)
        .map(|f| {
            // Position along the keys, 0 ..= keys - 1.
            let t = if frames == 1 {
                0.0
            } else {
                f as f32 * (keys.len() - 1) as f32 / (frames - 1) as f32
            };
            let i = (t.floor() as usize).min(keys.len().saturating_sub(2));
            let (a, b) = (keys[i], keys[(i + 1).min(keys.len() - 1)]);
            let u = (t - i as f32).clamp(0.0, 1.0);
            Camera {
                position: a.0.lerp(b.0, u),
                look_at: a.1.lerp(b.1, u),
                vfov_degrees: a.2 + (b.2 - a.2) * u,
                ..base.clone()
            }
        })
        .collect())
}
