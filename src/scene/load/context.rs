//! Where the document's values came from, and the checks that place their
//! errors there. The document has several sources: the file, then each
//! `--set` override's value, at offsets past the file's end (their spans are
//! moved there), so that one span says which source and line a value came
//! from. `Cx` holds them, with the translation and local origin every point
//! is read through.

use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use toml::de::DeValue;
use toml::Spanned;

use super::super::defaults::MAX_COORDINATE;
use super::super::rebase::{dvec3, Coord};
use crate::error::SceneError;

pub(super) type Span = Range<usize>;
pub(super) type Value<'a> = Spanned<DeValue<'a>>;

/// A text spliced into the document after the file (an override's value).
pub(super) struct Source<'a> {
    /// What errors about it show as their file (`--set shape[1].radius`).
    pub(super) name: PathBuf,
    pub(super) text: &'a str,
    /// Where the text starts in the document's offsets.
    pub(super) start: usize,
}

/// The reading context: the document's sources, and how points are moved.
pub(super) struct Cx<'a> {
    pub(super) file: PathBuf,
    text: &'a str,
    pub(super) base_dir: PathBuf,
    /// The texts after the file, in the order of their offsets.
    spliced: Vec<Source<'a>>,
    /// Added to every point as it is read (`load_scene_str_translated`).
    pub(super) translate: DVec3,
    /// The scene's local origin in the world's frame: points are stored
    /// relative to it.
    pub(super) origin: DVec3,
}

impl<'a> Cx<'a> {
    pub(super) fn new(text: &'a str, path: &Path, spliced: Vec<Source<'a>>) -> Self {
        Cx {
            file: path.to_path_buf(),
            text,
            base_dir: path.parent().unwrap_or(Path::new(".")).to_path_buf(),
            spliced,
            translate: DVec3::ZERO,
            origin: DVec3::ZERO,
        }
    }

    /// An error about what `span` covers.
    pub(super) fn err(&self, span: Span, field: &str, message: String) -> SceneError {
        let (file, line) = match self.spliced.iter().rev().find(|s| span.start >= s.start) {
            Some(s) => (s.name.clone(), line_of(s.text, span.start - s.start)),
            None => (self.file.clone(), line_of(self.text, span.start)),
        };
        SceneError {
            file,
            line,
            field: field.to_string(),
            message,
        }
    }

    /// A TOML syntax error: its line, and the key written on that line.
    pub(super) fn syntax_error(&self, e: &toml::de::Error) -> SceneError {
        let start = e.span().map_or(0, |s| s.start);
        SceneError {
            file: self.file.clone(),
            line: line_of(self.text, start),
            field: key_before(self.text, start).unwrap_or_else(|| "(syntax)".into()),
            message: e.message().trim().to_string(),
        }
    }
}

/// 1-based line of a byte offset.
pub(in crate::scene) fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// What ends the text before a key on its line: a comma, or the brace that
/// opens an inline table. (A constant, so that no brace sits unbalanced
/// inside a function's body for tools that count braces.)
const BEFORE_KEY: [char; 2] = [',', '\u{7b}'];

/// For a syntax error at a value, the key on the same line (`vfov = = 1` -> vfov).
fn key_before(text: &str, offset: usize) -> Option<String> {
    let end = offset.min(text.len());
    let start = text.as_bytes()[..end]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let line = text.get(start..end)?;
    let key = line.rsplit_once('=')?.0.rsplit(BEFORE_KEY).next()?.trim();
    (!key.is_empty()).then(|| key.to_string())
}

// ---- checks of values -----------------------------------------------------------------

impl Cx<'_> {
    pub(super) fn finite(&self, s: Span, field: &str, v: f32) -> Result<f32, SceneError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(s, field, format!("{v} is not a finite number")))
        }
    }

    pub(super) fn vec3(&self, s: Span, field: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        for x in v {
            self.finite(s.clone(), field, x)?;
        }
        let v = Vec3::from(v);
        if v.abs().max_element() > MAX_COORDINATE {
            return Err(self.err(
                s,
                field,
                format!(
                    "{:?} is too large: coordinates must stay within {MAX_COORDINATE:e}",
                    v.to_array()
                ),
            ));
        }
        Ok(v)
    }

    /// A point in f64, moved by the loader's translation: finite, and within
    /// MAX_COORDINATE of the world's origin.
    pub(super) fn point(&self, s: Span, field: &str, v: [Coord; 3]) -> Result<DVec3, SceneError> {
        for x in v {
            if !x.0.is_finite() {
                return Err(self.err(s, field, format!("{} is not a finite number", x.0)));
            }
        }
        let p = dvec3(v) + self.translate;
        if p.abs().max_element() > f64::from(MAX_COORDINATE) {
            return Err(self.err(
                s,
                field,
                format!(
                    "{:?} is too large: coordinates must stay within {MAX_COORDINATE:e}",
                    p.to_array()
                ),
            ));
        }
        Ok(p)
    }

    /// A point of the world's frame in the scene's local frame, in f32.
    pub(super) fn local(&self, p: DVec3) -> Vec3 {
        (p - self.origin).as_vec3()
    }

    pub(super) fn positive(&self, s: Span, field: &str, v: f32) -> Result<f32, SceneError> {
        let v = self.finite(s.clone(), field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(s, field, format!("{v} must be greater than 0")))
        }
    }

    pub(super) fn unit_rgb(&self, s: Span, field: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let c = self.vec3(s.clone(), field, v)?;
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            return Err(self.err(
                s,
                field,
                format!("{v:?}: each channel must be in [0, 1] (energy conservation)"),
            ));
        }
        Ok(c)
    }

    pub(super) fn nonnegative_rgb(
        &self,
        s: Span,
        field: &str,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        let c = self.vec3(s.clone(), field, v)?;
        if c.min_element() < 0.0 {
            return Err(self.err(s, field, format!("{v:?}: each channel must be >= 0")));
        }
        Ok(c)
    }

    pub(super) fn int_range(
        &self,
        s: Span,
        field: &str,
        v: i64,
        lo: i64,
        hi: i64,
    ) -> Result<i64, SceneError> {
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(self.err(
                s,
                field,
                format!("{v} is outside the allowed range {lo}..={hi}"),
            ))
        }
    }

    pub(super) fn nondegenerate(
        &self,
        s: Span,
        field: &str,
        a: Vec3,
        b: Vec3,
    ) -> Result<(), SceneError> {
        let scale = a.length() * b.length();
        if scale == 0.0 || a.cross(b).length() <= 1e-7 * scale {
            return Err(self.err(
                s,
                field,
                "the edges are zero or parallel: the shape has no area".into(),
            ));
        }
        Ok(())
    }
}
