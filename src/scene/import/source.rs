//! What the importers share, a leaf: the formats, the options, where the
//! files a scene names come from (`Files`), the converted result, and the
//! reading context (`Cx`) that refuses, or under --lenient notes, what
//! photonmap cannot render.

use std::path::{Path, PathBuf};

use crate::error::SceneError;

/// The formats read here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Pbrt,
    Mitsuba,
}

/// The format a scene path names by its extension (`.pbrt`, `.xml`), or
/// None for photonmap's own TOML.
pub fn format_of(path: &Path) -> Option<Format> {
    let ext = path.extension()?.to_str()?.to_ascii_lowercase();
    match ext.as_str() {
        "pbrt" => Some(Format::Pbrt),
        "xml" => Some(Format::Mitsuba),
        _ => None,
    }
}

/// How to import.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImportOptions {
    /// Map what photonmap cannot render to the nearest thing it can, with a
    /// note each, instead of refusing it.
    pub lenient: bool,
    /// Mitsuba's `-D key=value`: values for `$key` and `<default>`s.
    pub defines: Vec<(String, String)>,
}

/// A converted scene: its TOML, and the notes (one line each: what
/// `lenient` mapped, triangles dropped).
#[derive(Clone, Debug, PartialEq)]
pub struct Converted {
    pub toml: String,
    pub notes: Vec<String>,
}

/// Where the files a scene names come from.
pub trait Files {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>>;
}

/// The file system.
pub struct Disk;

impl Files for Disk {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        std::fs::read(path)
    }
}

/// No files at all (every include or mesh is missing): for the fuzz replay.
pub struct NoFiles;

impl Files for NoFiles {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        Err(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            format!("{} is not available", path.display()),
        ))
    }
}

/// What importers share while reading: the options and the notes.
pub struct Cx<'a> {
    pub files: &'a dyn Files,
    pub lenient: bool,
    pub notes: Vec<String>,
}

impl<'a> Cx<'a> {
    /// The context of one import: where it reads, and whether it is lenient.
    pub fn new(files: &'a dyn Files, opts: &ImportOptions) -> Self {
        Cx {
            files,
            lenient: opts.lenient,
            notes: Vec::new(),
        }
    }

    /// Something photonmap cannot render, at `file:line` (`what` names it):
    /// an error, or under --lenient a note that it became `instead`.
    pub fn unsupported(
        &mut self,
        file: &Path,
        line: usize,
        what: &str,
        instead: &str,
    ) -> Result<(), SceneError> {
        if self.lenient {
            self.notes
                .push(format!("{}:{line}: {what}: {instead}", file.display()));
            Ok(())
        } else {
            Err(SceneError::new(
                file,
                line,
                what,
                format!("photonmap cannot render this (--lenient: {instead})"),
            ))
        }
    }

    /// An emitting mesh's `unpaired` triangles, which make no parallelogram
    /// light: as `unsupported`, kept without emission (nothing when none).
    pub fn unpaired_triangles(
        &mut self,
        file: &Path,
        line: usize,
        what: &str,
        unpaired: usize,
    ) -> Result<(), SceneError> {
        if unpaired == 0 {
            return Ok(());
        }
        let what =
            format!("{what} emitting, but {unpaired} of its triangles make no parallelogram");
        self.unsupported(
            file,
            line,
            &what,
            "those triangles are kept without emission",
        )
    }

    /// A file the scene names, relative to `dir`.
    pub fn read(&self, dir: &Path, name: &str) -> Result<(PathBuf, Vec<u8>), String> {
        let path = dir.join(name);
        self.files
            .read(&path)
            .map(|b| (path.clone(), b))
            .map_err(|e| format!("cannot read {}: {e}", path.display()))
    }
}

/// The folder a scene file's relative paths start from.
pub fn dir_of(path: &Path) -> PathBuf {
    path.parent().map(Path::to_path_buf).unwrap_or_default()
}
