//! `--set` overrides (`key.path=value`): each value parsed as TOML and
//! spliced into the document before anything is read, its spans moved to
//! offsets past the file's end (and past the overrides before it), so that
//! it is validated exactly like the file and every error about it names the
//! override as its file (`context::Cx::err`).

use std::path::PathBuf;

use toml::de::{DeString, DeTable, DeValue};
use toml::Spanned;

use super::context::{line_of, Source, Span, Value};
use crate::error::SceneError;

pub(super) struct Override<'a> {
    /// The key path as given, e.g. `shape[1].radius`.
    key: &'a str,
    /// The value's TOML text.
    value: &'a str,
    /// Where the value's text starts in the document's offsets.
    start: usize,
}

/// The overrides, in order, each placed after the file (`text`) and the
/// ones before it.
pub(super) fn placed<'a>(text: &str, overrides: &'a [(String, String)]) -> Vec<Override<'a>> {
    let mut start = text.len() + 1;
    overrides
        .iter()
        .map(|(key, value)| {
            let value = value.trim();
            let o = Override {
                key: key.trim(),
                value,
                start,
            };
            start += value.len() + 1;
            o
        })
        .collect()
}

impl<'a> Override<'a> {
    /// What errors about this override show as their file.
    fn name(&self) -> PathBuf {
        PathBuf::from(format!("--set {}", self.key))
    }

    /// The override as a source of the document.
    pub(super) fn source(&self) -> Source<'a> {
        Source {
            name: self.name(),
            text: self.value,
            start: self.start,
        }
    }

    /// Splices the override into the document, its spans moved to its offsets.
    pub(super) fn apply(&self, root: &mut DeTable<'a>) -> Result<(), SceneError> {
        let fail = |line: usize, message: String| SceneError {
            file: self.name(),
            line,
            field: self.key.to_string(),
            message,
        };
        let value = DeValue::parse(self.value).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            let message = format!(
                "{:?} is not a TOML value: {}",
                self.value,
                e.message().trim()
            );
            fail(line_of(self.value, at), message)
        })?;
        let path = key_path(self.key).map_err(|m| fail(1, m))?;
        let span = self.start..self.start + self.value.len();
        set_at(root, &path, moved(value, self.start), &span).map_err(|m| fail(1, m))
    }
}
/// One step of an override's key path: a key, and an index into the array
/// of tables it names.
type Step = (String, Option<usize>);

/// `shape[1].radius` -> [("shape", Some(1)), ("radius", None)].
fn key_path(path: &str) -> Result<Vec<Step>, String> {
    let bad = || {
        format!("{path:?} is not a key path (keys joined by dots, each with an optional [index], e.g. shape[1].radius)")
    };
    let key_char = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
    path.split('.')
        .map(|step| {
            let (key, index) = match step.split_once('[') {
                None => (step, None),
                Some((key, rest)) => {
                    let digits = rest.strip_suffix(']').ok_or_else(bad)?;
                    (key, Some(digits.parse::<usize>().map_err(|_| bad())?))
                }
            };
            if key.is_empty() || !key.chars().all(key_char) {
                return Err(bad());
            }
            Ok((key.to_string(), index))
        })
        .collect()
}

/// Sets `value` at `path` in `table`, creating missing tables on the way;
/// an index one past an array's end appends.
fn set_at<'a>(
    table: &mut DeTable<'a>,
    path: &[Step],
    value: Value<'a>,
    span: &Span,
) -> Result<(), String> {
    let Some(((key, index), rest)) = path.split_first() else {
        return Err("an empty key path".into());
    };
    let new_key = || Spanned::new(span.clone(), DeString::Owned(key.clone()));
    let slot = match index {
        None if rest.is_empty() => {
            table.remove(key.as_str());
            table.insert(new_key(), value);
            return Ok(());
        }
        None => table
            .entry(new_key())
            .or_insert_with(|| Spanned::new(span.clone(), DeValue::Table(DeTable::new()))),
        Some(i) => {
            let items = match table.get_mut(key.as_str()).map(Spanned::get_mut) {
                Some(DeValue::Array(items)) => items,
                Some(other) => {
                    return Err(format!(
                        "`{key}` is not an array (its value is of type {})",
                        other.type_str()
                    ))
                }
                None if *i == 0 && rest.is_empty() => {
                    let items = std::iter::once(value).collect();
                    table.insert(new_key(), Spanned::new(span.clone(), DeValue::Array(items)));
                    return Ok(());
                }
                None => return Err(format!("the scene has no `{key}`")),
            };
            let len = items.len();
            if *i == len && rest.is_empty() {
                items.push(value);
                return Ok(());
            }
            match items.get_mut(*i) {
                Some(item) if rest.is_empty() => {
                    *item = value;
                    return Ok(());
                }
                Some(item) => item,
                None => return Err(format!("`{key}` has {len} entries: there is no {key}[{i}]")),
            }
        }
    };
    match slot.get_mut() {
        DeValue::Table(inner) => set_at(inner, rest, value, span),
        other => Err(format!(
            "`{key}` is not a table (its value is of type {})",
            other.type_str()
        )),
    }
}

/// `value` with every span moved by `by`.
fn moved(value: Value<'_>, by: usize) -> Value<'_> {
    let span = value.span();
    let span = span.start + by..span.end + by;
    let inner = match value.into_inner() {
        DeValue::Array(items) => DeValue::Array(items.into_iter().map(|v| moved(v, by)).collect()),
        DeValue::Table(map) => DeValue::Table(
            map.into_iter()
                .map(|(k, v)| {
                    let ks = k.span();
                    let k = Spanned::new(ks.start + by..ks.end + by, k.into_inner());
                    (k, moved(v, by))
                })
                .collect(),
        ),
        other => other,
    };
    Spanned::new(span, inner)
}
