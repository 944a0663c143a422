//! A scene file converted: read by its format's importer into a `Model`,
//! checked for a camera and a light, and written as TOML.

use std::path::Path;

use super::source::{format_of, Converted, Disk, Files, Format, ImportOptions};
use super::{mitsuba, model, pbrt};
use crate::error::SceneError;

/// Reads and converts a pbrt or Mitsuba scene file.
pub fn convert_file(path: &Path, opts: &ImportOptions) -> Result<Converted, SceneError> {
    let format = format_of(path)
        .ok_or_else(|| SceneError::new(path, 0, "(file)", "not a .pbrt or .xml scene".into()))?;
    let bytes = Disk.read(path).map_err(|e| {
        SceneError::new(
            path,
            0,
            "(file)",
            format!("cannot read the scene file: {e}"),
        )
    })?;
    convert_bytes(format, &bytes, path, &Disk, opts)
}

/// Converts a scene from its bytes; `path` names it in errors and anchors
/// the paths it names.
pub fn convert_bytes(
    format: Format,
    bytes: &[u8],
    path: &Path,
    files: &dyn Files,
    opts: &ImportOptions,
) -> Result<Converted, SceneError> {
    let mut model = match format {
        Format::Pbrt => pbrt::read(bytes, path, files, opts)?,
        Format::Mitsuba => mitsuba::read(bytes, path, files, opts)?,
    };
    if model.camera.is_none() {
        return Err(SceneError::new(
            path,
            0,
            "camera",
            "the scene has no camera".into(),
        ));
    }
    if model.emitters.is_empty() {
        return Err(SceneError::new(
            path,
            0,
            "light",
            "the scene has no light photonmap can render".into(),
        ));
    }
    if model.degenerate > 0 {
        model.notes.push(format!(
            "{}: dropped {} triangles with no area",
            path.display(),
            model.degenerate
        ));
    }
    Ok(Converted {
        toml: model::to_toml(&model),
        notes: model.notes,
    })
}
