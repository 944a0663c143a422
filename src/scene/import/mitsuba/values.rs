//! An XML object's properties (a leaf of the Mitsuba reader): each child
//! element read into a typed value with its line, `$name` substituted, the
//! Mitsuba 0.6 camelCase names taken as Mitsuba 3's, and transforms
//! composed. `Props::finish` refuses a property nothing asked for, as
//! Mitsuba refuses unreferenced properties.

use std::cell::Cell;
use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3};
use roxmltree::Node;

use crate::error::SceneError;

/// Where a node is: its file and the document's text positions.
#[derive(Clone, Copy)]
pub struct At<'a, 'input> {
    pub file: &'a Path,
    pub doc: &'a roxmltree::Document<'input>,
    pub defines: &'a HashMap<String, String>,
}

impl At<'_, '_> {
    pub fn line(&self, n: Node) -> usize {
        self.doc.text_pos_at(n.range().start).row as usize
    }

    pub fn err(&self, n: Node, field: &str, message: String) -> SceneError {
        SceneError::new(self.file, self.line(n), field, message)
    }

    /// An attribute with `$name` replaced by its value.
    pub fn attr(&self, n: Node, name: &str) -> Result<Option<String>, SceneError> {
        let Some(v) = n.attribute(name) else {
            return Ok(None);
        };
        substitute(v, self.defines)
            .map(Some)
            .map_err(|m| self.err(n, name, m))
    }

    pub fn req(&self, n: Node, name: &str) -> Result<String, SceneError> {
        self.attr(n, name)?.ok_or_else(|| {
            self.err(
                n,
                n.tag_name().name(),
                format!("<{}> needs `{name}`", n.tag_name().name()),
            )
        })
    }
}

/// `$name` references replaced from `defines`.
pub fn substitute(v: &str, defines: &HashMap<String, String>) -> Result<String, String> {
    let mut out = String::new();
    let mut rest = v;
    while let Some(i) = rest.find('$') {
        out.push_str(&rest[..i]);
        let after = &rest[i + 1..];
        let end = after
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
            .unwrap_or(after.len());
        let name = &after[..end];
        match defines.get(name) {
            Some(x) if !name.is_empty() => out.push_str(x),
            _ => {
                return Err(format!(
                    "${name} has no value: give it with -D {name}=... or a <default>"
                ))
            }
        }
        rest = &after[end..];
    }
    out.push_str(rest);
    Ok(out)
}

/// Mitsuba 0.6's camelCase property names, as Mitsuba 3 spells them.
pub fn snake(name: &str) -> String {
    const ALIASES: &[(&str, &str)] = &[
        ("toWorld", "to_world"),
        ("fovAxis", "fov_axis"),
        ("sampleCount", "sample_count"),
        ("intIOR", "int_ior"),
        ("extIOR", "ext_ior"),
        ("flipNormals", "flip_normals"),
        ("faceNormals", "face_normals"),
        ("maxDepth", "max_depth"),
        ("photonCount", "photon_count"),
        ("initialRadius", "initial_radius"),
        ("maxPasses", "max_passes"),
        ("nearClip", "near_clip"),
        ("farClip", "far_clip"),
        ("focusDistance", "focus_distance"),
        ("focalLength", "focal_length"),
        ("specularReflectance", "specular_reflectance"),
        ("diffuseReflectance", "diffuse_reflectance"),
        ("rfilter", "rfilter"),
        ("pixelFormat", "pixel_format"),
        ("componentFormat", "component_format"),
        ("shutterOpen", "shutter_open"),
        ("shutterClose", "shutter_close"),
        ("granularity", "granularity"),
        ("rrDepth", "rr_depth"),
        ("hideEmitters", "hide_emitters"),
        ("banner", "banner"),
    ];
    ALIASES
        .iter()
        .find(|(a, _)| *a == name)
        .map_or_else(|| name.to_string(), |(_, b)| b.to_string())
}

/// A property's value.
#[derive(Clone, Debug)]
pub enum Value {
    Num(f64),
    Bool(bool),
    Str(String),
    Rgb([f64; 3]),
    Vec3(DVec3),
    /// What photonmap cannot take: a spectrum by wavelengths, a texture.
    Other(String),
    Transform(DMat4),
    /// A nested object or a `<ref>`: its element.
    Object,
}

pub struct Prop<'a, 'input> {
    pub name: String,
    pub value: Value,
    pub node: Node<'a, 'input>,
    used: Cell<bool>,
}

/// An object element's properties.
pub struct Props<'a, 'input> {
    pub props: Vec<Prop<'a, 'input>>,
    pub node: Node<'a, 'input>,
    /// `<shape type="ply">` and so on, for messages.
    pub what: String,
}

fn numbers(s: &str) -> Result<Vec<f64>, String> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| {
            t.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| format!("`{t}` is not a number"))
        })
        .collect()
}

fn three(at: &At, n: Node) -> Result<DVec3, SceneError> {
    if let Some(v) = at.attr(n, "value")? {
        let v = numbers(&v).map_err(|m| at.err(n, "value", m))?;
        return match v.as_slice() {
            [x] => Ok(DVec3::splat(*x)),
            [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
            _ => Err(at.err(n, "value", "takes 1 or 3 numbers".into())),
        };
    }
    let c = |k: &str, d: f64| -> Result<f64, SceneError> {
        match at.attr(n, k)? {
            Some(s) => numbers(&s)
                .ok()
                .filter(|v| v.len() == 1)
                .map(|v| v[0])
                .ok_or_else(|| at.err(n, k, format!("`{s}` is not a number"))),
            None => Ok(d),
        }
    };
    Ok(DVec3::new(c("x", 0.0)?, c("y", 0.0)?, c("z", 0.0)?))
}

/// One `<transform>`'s steps, composed as Mitsuba does (each step applies
/// after those before it).
fn transform(at: &At, n: Node) -> Result<DMat4, SceneError> {
    let mut m = DMat4::IDENTITY;
    for c in n.children().filter(Node::is_element) {
        let step = match c.tag_name().name() {
            "translate" => DMat4::from_translation(three(at, c)?),
            "scale" => {
                let has_xyz = ["x", "y", "z"].iter().any(|k| c.attribute(*k).is_some());
                let v = if has_xyz {
                    let get = |k: &str| -> Result<f64, SceneError> {
                        at.attr(c, k)?.map_or(Ok(1.0), |s| {
                            s.trim()
                                .parse()
                                .map_err(|_| at.err(c, k, format!("`{s}` is not a number")))
                        })
                    };
                    DVec3::new(get("x")?, get("y")?, get("z")?)
                } else {
                    three(at, c)?
                };
                DMat4::from_scale(v)
            }
            "rotate" => {
                let angle: f64 = at
                    .req(c, "angle")?
                    .trim()
                    .parse()
                    .map_err(|_| at.err(c, "angle", "is not a number".into()))?;
                let axis = three(at, c)?;
                if axis.length() == 0.0 {
                    return Err(at.err(c, "rotate", "the axis is zero".into()));
                }
                DMat4::from_axis_angle(axis.normalize(), angle.to_radians())
            }
            "matrix" => {
                let v = numbers(&at.req(c, "value")?).map_err(|m| at.err(c, "value", m))?;
                let a: [f64; 16] = v
                    .try_into()
                    .map_err(|_| at.err(c, "value", "a matrix takes 16 numbers".into()))?;
                DMat4::from_cols_array(&a).transpose()
            }
            "lookat" => {
                let p = |k: &str| -> Result<DVec3, SceneError> {
                    let v = numbers(&at.req(c, k)?).map_err(|m| at.err(c, k, m))?;
                    match v.as_slice() {
                        [x, y, z] => Ok(DVec3::new(*x, *y, *z)),
                        _ => Err(at.err(c, k, "takes 3 numbers".into())),
                    }
                };
                let (o, t) = (p("origin")?, p("target")?);
                let up = if c.attribute("up").is_some() {
                    p("up")?
                } else {
                    DVec3::Y
                };
                let dir = (t - o).normalize();
                let left = up.normalize().cross(dir).normalize();
                if !dir.is_finite() || !left.is_finite() {
                    return Err(at.err(
                        c,
                        "lookat",
                        "origin equals target, or up is along the view".into(),
                    ));
                }
                let new_up = dir.cross(left);
                DMat4::from_cols(
                    left.extend(0.0),
                    new_up.extend(0.0),
                    dir.extend(0.0),
                    o.extend(1.0),
                )
            }
            other => return Err(at.err(c, other, format!("unknown transform step <{other}>"))),
        };
        m = step * m;
    }
    if !m.is_finite() || m.determinant() == 0.0 {
        return Err(at.err(n, "transform", "the transform is singular".into()));
    }
    Ok(m)
}

/// The value of one property element.
fn value(at: &At, c: Node) -> Result<Value, SceneError> {
    let tag = c.tag_name().name();
    Ok(match tag {
        "float" | "integer" => {
            let s = at.req(c, "value")?;
            Value::Num(
                s.trim()
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| at.err(c, "value", format!("<{tag}> `{s}` is not a number")))?,
            )
        }
        "boolean" => match at.req(c, "value")?.trim() {
            "true" => Value::Bool(true),
            "false" => Value::Bool(false),
            s => return Err(at.err(c, "value", format!("<boolean> `{s}` is not true or false"))),
        },
        "string" => Value::Str(at.req(c, "value")?),
        "rgb" | "color" => {
            let v = three(at, c)?;
            if v.min_element() < 0.0 {
                return Err(at.err(c, "value", "an rgb value is negative".into()));
            }
            Value::Rgb(v.to_array())
        }
        "spectrum" => match at.attr(c, "value")? {
            Some(s) => match numbers(&s).as_deref() {
                Ok([x]) if *x >= 0.0 => Value::Rgb([*x; 3]),
                _ => Value::Other(format!("<spectrum value=\"{s}\">")),
            },
            None => Value::Other("<spectrum>".into()),
        },
        "point" | "vector" => Value::Vec3(three(at, c)?),
        "transform" => Value::Transform(transform(at, c)?),
        "texture" => Value::Other(format!(
            "<texture type=\"{}\">",
            c.attribute("type").unwrap_or("")
        )),
        _ => Value::Object,
    })
}

impl<'a, 'input> Props<'a, 'input> {
    pub fn read(at: &At, node: Node<'a, 'input>) -> Result<Self, SceneError> {
        let what = format!(
            "<{} type=\"{}\">",
            node.tag_name().name(),
            node.attribute("type").unwrap_or("")
        );
        let mut props: Vec<Prop> = Vec::new();
        for c in node.children().filter(Node::is_element) {
            let name = snake(&at.attr(c, "name")?.unwrap_or_default());
            let v = value(at, c)?;
            if !name.is_empty()
                && !matches!(v, Value::Object)
                && props.iter().any(|p| p.name == name)
            {
                return Err(at.err(c, &name, format!("`{name}` is given twice")));
            }
            props.push(Prop {
                name,
                value: v,
                node: c,
                used: Cell::new(false),
            });
        }
        Ok(Props { props, node, what })
    }

    pub fn get(&self, name: &str) -> Option<&Prop<'a, 'input>> {
        let p = self
            .props
            .iter()
            .find(|p| p.name == name && !matches!(p.value, Value::Object))?;
        p.used.set(true);
        Some(p)
    }

    /// The nested objects and references (`<bsdf>`, `<emitter>`, `<ref>`...).
    pub fn objects(&self) -> impl Iterator<Item = &Prop<'a, 'input>> {
        self.props
            .iter()
            .filter(|p| matches!(p.value, Value::Object))
            .inspect(|p| p.used.set(true))
    }

    fn wrong(&self, at: &At, p: &Prop, wants: &str) -> SceneError {
        at.err(
            p.node,
            &format!("{} {}", self.what, p.name),
            format!("is <{}>; it must be {wants}", p.node.tag_name().name()),
        )
    }

    pub fn float(&self, at: &At, name: &str, default: f64) -> Result<f64, SceneError> {
        match self.get(name) {
            None => Ok(default),
            Some(Prop {
                value: Value::Num(x),
                ..
            }) => Ok(*x),
            Some(p) => Err(self.wrong(at, p, "a <float>")),
        }
    }

    pub fn bool(&self, at: &At, name: &str, default: bool) -> Result<bool, SceneError> {
        match self.get(name) {
            None => Ok(default),
            Some(Prop {
                value: Value::Bool(x),
                ..
            }) => Ok(*x),
            Some(p) => Err(self.wrong(at, p, "a <boolean>")),
        }
    }

    pub fn string(&self, at: &At, name: &str) -> Result<Option<String>, SceneError> {
        match self.get(name) {
            None => Ok(None),
            Some(Prop {
                value: Value::Str(x),
                ..
            }) => Ok(Some(x.clone())),
            Some(p) => Err(self.wrong(at, p, "a <string>")),
        }
    }

    pub fn point(&self, at: &At, name: &str) -> Result<Option<DVec3>, SceneError> {
        match self.get(name) {
            None => Ok(None),
            Some(Prop {
                value: Value::Vec3(x),
                ..
            }) => Ok(Some(*x)),
            Some(p) => Err(self.wrong(at, p, "a <point>")),
        }
    }

    pub fn transform(&self, at: &At, name: &str) -> Result<DMat4, SceneError> {
        match self.get(name) {
            None => Ok(DMat4::IDENTITY),
            Some(Prop {
                value: Value::Transform(m),
                ..
            }) => Ok(*m),
            Some(p) => Err(self.wrong(at, p, "a <transform>")),
        }
    }

    /// A colour: Ok(None) absent, Err(description) for what photonmap
    /// cannot take.
    pub fn colour(
        &self,
        at: &At,
        name: &str,
    ) -> Result<Option<Result<[f64; 3], String>>, SceneError> {
        match self.get(name) {
            None => Ok(None),
            Some(Prop {
                value: Value::Rgb(c),
                ..
            }) => Ok(Some(Ok(*c))),
            Some(Prop {
                value: Value::Num(x),
                ..
            }) if *x >= 0.0 => Ok(Some(Ok([*x; 3]))),
            Some(Prop {
                value: Value::Other(d),
                ..
            }) => Ok(Some(Err(d.clone()))),
            Some(p) => Err(self.wrong(at, p, "an <rgb>")),
        }
    }

    pub fn line_of(&self, at: &At, name: &str) -> usize {
        self.props
            .iter()
            .find(|p| p.name == name)
            .map_or_else(|| at.line(self.node), |p| at.line(p.node))
    }

    pub fn ignore(&self, names: &[&str]) {
        for p in &self.props {
            if names.contains(&p.name.as_str()) {
                p.used.set(true);
            }
        }
    }

    pub fn ignore_all(&self) {
        self.props.iter().for_each(|p| p.used.set(true));
    }

    /// Refuses a property nothing asked for.
    pub fn finish(&self, at: &At) -> Result<(), SceneError> {
        match self.props.iter().find(|p| !p.used.get()) {
            Some(p) => Err(at.err(
                p.node,
                &format!("{} {}", self.what, p.name),
                format!(
                    "unknown property `{}` (<{}>)",
                    p.name,
                    p.node.tag_name().name()
                ),
            )),
            None => Ok(()),
        }
    }
}
