//! `Table`: one table of the spanned TOML document, read field by field as
//! typed values, every error placed at the span of the key, value or table
//! it is about; and `Strict`, the serde deserializer it reads values
//! through, which refuses arrays longer than what they are read into.

use std::collections::BTreeMap;

use glam::{DVec3, Vec3};
use serde::de::value::SeqDeserializer;
use serde::de::{DeserializeOwned, IntoDeserializer};
use toml::de::{DeTable, DeValue, ValueDeserializer};
use toml::Spanned;

use super::super::rebase::Coord;
use super::context::{Cx, Span, Value};
use crate::error::SceneError;

/// A tagged table's kinds: the `type` value, the kind, and its other fields.
pub(super) type Kinds<K> = [(&'static str, K, &'static [&'static str])];

/// One table of the document being read: every error about its fields is
/// placed at the span of the key, value or table it is about.
pub(super) struct Table<'c, 'a> {
    pub(super) cx: &'c Cx<'a>,
    /// Dotted path of the table (`camera`, `materials.gold`, `shape[6]`);
    /// empty at the top level.
    path: String,
    /// The header (`[camera]`, `[[shape]]`) or the whole inline table; 0..0
    /// for a table that is not in the document (its fields take defaults).
    pub(super) span: Span,
    pub(super) map: &'c DeTable<'a>,
}

impl<'c, 'a> Table<'c, 'a> {
    /// The whole document, as the top-level table.
    pub(super) fn document(cx: &'c Cx<'a>, root: &'c DeTable<'a>) -> Self {
        Table {
            cx,
            path: String::new(),
            span: 0..0,
            map: root,
        }
    }

    /// The table `value`, at `path`, written as `key`.
    pub(super) fn new(
        cx: &'c Cx<'a>,
        path: String,
        key: &str,
        value: &'c Value<'a>,
    ) -> Result<Self, SceneError> {
        match value.get_ref() {
            DeValue::Table(map) => Ok(Table {
                cx,
                path,
                span: value.span(),
                map,
            }),
            other => Err(cx.err(
                value.span(),
                key,
                format!(
                    "invalid type: {}, expected a table{}",
                    other.type_str(),
                    at_path(&path, "")
                ),
            )),
        }
    }

    /// The dotted path of a field of this table.
    pub(super) fn field(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The sub-table `key`; when it is absent, `absent` (empty: its fields
    /// take their defaults) or, with None, a missing-field error.
    pub(super) fn table(
        &self,
        key: &str,
        absent: Option<&'c DeTable<'a>>,
    ) -> Result<Self, SceneError> {
        match (self.map.get(key), absent) {
            (Some(value), _) => Table::new(self.cx, self.field(key), key, value),
            (None, Some(map)) => Ok(Table {
                cx: self.cx,
                path: self.field(key),
                span: 0..0,
                map,
            }),
            (None, None) => Err(self.missing(key)),
        }
    }

    /// The tables of the array `key` (`[[shape]]`, or an inline array of
    /// inline tables), at paths `key[0]`, `key[1]`...; none when absent.
    pub(super) fn array(&self, key: &str) -> Result<Vec<Self>, SceneError> {
        let Some(value) = self.map.get(key) else {
            return Ok(Vec::new());
        };
        let DeValue::Array(items) = value.get_ref() else {
            return Err(self.cx.err(
                value.span(),
                key,
                format!(
                    "invalid type: {}, expected an array of tables ([[{key}]])",
                    value.get_ref().type_str()
                ),
            ));
        };
        items
            .iter()
            .enumerate()
            .map(|(i, item)| {
                let path = format!("{}[{i}]", self.field(key));
                Table::new(self.cx, path.clone(), &path, item)
            })
            .collect()
    }

    /// Refuses any key but `allowed` (and `type` in a tagged table), at the
    /// first unknown key in the text.
    pub(super) fn only(&self, allowed: &[&str], tagged: bool) -> Result<(), SceneError> {
        let unknown = self
            .map
            .keys()
            .filter(|k| {
                !(allowed.contains(&k.get_ref().as_ref()) || tagged && *k.get_ref() == "type")
            })
            .min_by_key(|k| k.span().start);
        match unknown {
            None => Ok(()),
            Some(key) => Err(self.cx.err(
                key.span(),
                key.get_ref(),
                format!(
                    "unknown field `{}`{}, expected {}",
                    key.get_ref(),
                    within(&self.path),
                    one_of(allowed)
                ),
            )),
        }
    }

    /// A tagged table's `type` among `kinds`; the table may hold that kind's
    /// fields only.
    pub(super) fn kind<K: Copy>(&self, kinds: &Kinds<K>) -> Result<K, SceneError> {
        let asked = self.req::<String>("type")?;
        let Some(&(_, kind, fields)) = kinds.iter().find(|k| k.0 == asked.get_ref()) else {
            let names: Vec<&str> = kinds.iter().map(|k| k.0).collect();
            return Err(self.cx.err(
                asked.span(),
                "type",
                format!(
                    "unknown variant `{}`{}, expected {}",
                    asked.get_ref(),
                    within(&self.field("type")),
                    one_of(&names)
                ),
            ));
        };
        self.only(fields, true)?;
        Ok(kind)
    }

    /// The field `key` as a `T`, with its value's span; None when absent.
    pub(super) fn get<T: DeserializeOwned>(
        &self,
        key: &str,
    ) -> Result<Option<Spanned<T>>, SceneError> {
        let Some(value) = self.map.get(key) else {
            return Ok(None);
        };
        let span = value.span();
        match T::deserialize(Strict(value.clone())) {
            Ok(v) => Ok(Some(Spanned::new(span, v))),
            Err(e) => {
                // An element's own span when the error is about one.
                let at = e
                    .span
                    .filter(|s| s.start >= span.start && s.end <= span.end)
                    .unwrap_or(span);
                Err(self.cx.err(
                    at,
                    key,
                    format!("{}{}", e.message.trim(), at_path(&self.path, key)),
                ))
            }
        }
    }

    /// The field `key`, which must be present.
    pub(super) fn req<T: DeserializeOwned>(&self, key: &str) -> Result<Spanned<T>, SceneError> {
        self.get(key)?.ok_or_else(|| self.missing(key))
    }

    /// The field `key`, or `default` placed at the table when absent.
    pub(super) fn or<T: DeserializeOwned>(
        &self,
        key: &str,
        default: T,
    ) -> Result<Spanned<T>, SceneError> {
        Ok(self
            .get(key)?
            .unwrap_or_else(|| Spanned::new(self.span.clone(), default)))
    }

    fn missing(&self, key: &str) -> SceneError {
        self.cx.err(
            self.span.clone(),
            key,
            format!("missing field `{key}`{}", within(&self.path)),
        )
    }

    /// An integer field in lo..=hi (`default` when absent; None: required).
    pub(super) fn int(
        &self,
        key: &str,
        default: Option<u32>,
        lo: i64,
        hi: i64,
    ) -> Result<u32, SceneError> {
        let at = match default {
            Some(d) => self.or(key, i64::from(d))?,
            None => self.req::<i64>(key)?,
        };
        let v = self
            .cx
            .int_range(at.span(), &self.field(key), *at.get_ref(), lo, hi)?;
        Ok(v as u32)
    }

    /// A finite number > 0 (`default` when absent; None: required).
    pub(super) fn positive(&self, key: &str, default: Option<f32>) -> Result<f32, SceneError> {
        let at = match default {
            Some(d) => self.or(key, d)?,
            None => self.req::<f32>(key)?,
        };
        self.cx.positive(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required point or vector.
    fn vec3(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[f32; 3]>(key)?;
        self.check_vec3(key, &at)
    }

    pub(super) fn check_vec3(&self, key: &str, at: &Spanned<[f32; 3]>) -> Result<Vec3, SceneError> {
        self.cx.vec3(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required point: read in f64, moved and checked (`Cx::point`), and
    /// stored rebased, in f32.
    pub(super) fn point(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[Coord; 3]>(key)?;
        Ok(self.cx.local(self.check_point(key, &at)?))
    }

    /// A point in the world's frame, in f64 (not yet rebased).
    pub(super) fn check_point(
        &self,
        key: &str,
        at: &Spanned<[Coord; 3]>,
    ) -> Result<DVec3, SceneError> {
        self.cx.point(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required colour with each channel in [0, 1].
    pub(super) fn unit_rgb(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[f32; 3]>(key)?;
        self.cx.unit_rgb(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required colour with each channel >= 0.
    pub(super) fn nonnegative_rgb(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[f32; 3]>(key)?;
        self.cx
            .nonnegative_rgb(at.span(), &self.field(key), *at.get_ref())
    }

    /// `corner`, `edge1` and `edge2` of a parallelogram of nonzero area.
    pub(super) fn parallelogram(&self) -> Result<(Vec3, Vec3, Vec3), SceneError> {
        let corner = self.point("corner")?;
        let edge1 = self.vec3("edge1")?;
        let edge2_at = self.req::<[f32; 3]>("edge2")?;
        let edge2 = self.check_vec3("edge2", &edge2_at)?;
        self.cx
            .nondegenerate(edge2_at.span(), &self.field("edge2"), edge1, edge2)?;
        Ok((corner, edge1, edge2))
    }

    /// The index of the material the table names.
    pub(super) fn material(&self, names: &BTreeMap<String, usize>) -> Result<usize, SceneError> {
        let at = self.req::<String>("material")?;
        self.material_named(names, &at, "material")
    }

    /// The index of the material named by the value `at` of field `key`.
    pub(super) fn material_named(
        &self,
        names: &BTreeMap<String, usize>,
        at: &Spanned<String>,
        key: &str,
    ) -> Result<usize, SceneError> {
        names.get(at.get_ref()).copied().ok_or_else(|| {
            let known: Vec<_> = names.keys().cloned().collect();
            self.cx.err(
                at.span(),
                &self.field(key),
                format!(
                    "no material named {:?} (defined: {})",
                    at.get_ref(),
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        })
    }
}

/// One value read through serde. Unlike toml's own deserializer it refuses
/// arrays longer than what they are read into (`[1.0, 2.0, 3.0, 4.0]` as a
/// `[f32; 3]`), and every error keeps the span of the value (the array or
/// element) it is about.
pub(super) struct Strict<'a>(pub(super) Value<'a>);

#[derive(Debug)]
pub(super) struct StrictError {
    message: String,
    span: Option<Span>,
}

impl std::fmt::Display for StrictError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for StrictError {}

impl serde::de::Error for StrictError {
    fn custom<T: std::fmt::Display>(message: T) -> Self {
        StrictError {
            message: message.to_string(),
            span: None,
        }
    }
}

impl<'de> serde::Deserializer<'de> for Strict<'de> {
    type Error = StrictError;

    fn deserialize_any<V: serde::de::Visitor<'de>>(
        self,
        visitor: V,
    ) -> Result<V::Value, StrictError> {
        let span = self.0.span();
        let placed = |mut e: StrictError| {
            e.span.get_or_insert_with(|| span.clone());
            e
        };
        match self.0.into_inner() {
            DeValue::Array(items) => {
                let mut seq = SeqDeserializer::new(items.into_iter().map(Strict));
                let v = visitor.visit_seq(&mut seq).map_err(placed)?;
                seq.end().map_err(placed)?;
                Ok(v)
            }
            other => ValueDeserializer::from(Spanned::new(span.clone(), other))
                .deserialize_any(visitor)
                .map_err(|e| StrictError {
                    message: e.message().to_string(),
                    span: e.span().or(Some(span.clone())),
                }),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

impl<'de> IntoDeserializer<'de, StrictError> for Strict<'de> {
    type Deserializer = Self;

    fn into_deserializer(self) -> Self {
        self
    }
}

/// " in PATH", or nothing at the top level.
fn within(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!(" in {path}")
    }
}

/// ", at PATH.KEY" for a field of a table (", at PATH" for the table
/// itself), or nothing at the top level.
fn at_path(path: &str, key: &str) -> String {
    match (path, key) {
        ("", _) => String::new(),
        (_, "") => format!(", at {path}"),
        _ => format!(", at {path}.{key}"),
    }
}

/// "`a`" or "one of `a`, `b`".
fn one_of(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.len() {
        1 => quoted[0].clone(),
        _ => format!("one of {}", quoted.join(", ")),
    }
}
