//! Mitsuba 3 XML scenes.

use std::path::Path;

use super::model::Model;
use super::source::{Files, ImportOptions};
use crate::error::SceneError;

/// Reads a Mitsuba 3 XML file into a model.
pub fn read(
    _bytes: &[u8],
    path: &Path,
    _files: &dyn Files,
    _opts: &ImportOptions,
) -> Result<Model, SceneError> {
    Err(SceneError::new(
        path,
        0,
        "(file)",
        "Mitsuba scenes are not read yet".into(),
    ))
}
