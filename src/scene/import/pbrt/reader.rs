//! pbrt's directives and the graphics state they change: transforms
//! compose as in pbrt (each post-multiplies the current transform),
//! AttributeBegin/End save and restore the state, Include/Import read
//! another file, object instances are flattened; the typed directives hand
//! their parameters to `objects.rs`.

use std::collections::HashMap;
use std::path::Path;

use glam::{DMat4, DVec3};

use super::super::geometry::Xf;
use super::super::model::{CameraSpec, Mat, Model};
use super::super::source::{Cx, Files, ImportOptions};
use super::lexer::{self, Tok, Token};
use super::objects;
use super::params::Params;
use super::state::{PendingShape, Reader, State, MAX_INCLUDE_DEPTH};
use crate::error::SceneError;

/// Reads a pbrt-v4 file (and what it includes) into a model.
pub fn read(
    bytes: &[u8],
    path: &Path,
    files: &dyn Files,
    opts: &ImportOptions,
) -> Result<Model, SceneError> {
    let mut r = Reader {
        cx: Cx::new(files, opts),
        model: Model::for_file(path),
        state: State {
            ctm: DMat4::IDENTITY,
            reverse: false,
            material: Some(("diffuse".into(), Mat::Diffuse([0.5; 3]))),
            area: None,
        },
        stack: Vec::new(),
        transforms: Vec::new(),
        named: HashMap::new(),
        coordinate_systems: HashMap::new(),
        objects: HashMap::new(),
        defining: None,
        dir: super::super::source::dir_of(path),
        depth: 0,
        spp: None,
        camera: None,
        film: (1280, 720),
    };
    r.file(bytes, path)?;
    if let Some(spp) = r.spp {
        r.model.hints.spp = Some(spp);
        if let Some((it @ None, ..)) = &mut r.model.hints.sppm {
            *it = Some(spp);
        }
    }
    if let Some(c) = r.camera {
        let (w, h) = r.film;
        // pbrt's fov spans the shorter side
        let vfov = if h <= w {
            c.fov
        } else {
            2.0 * ((c.fov.to_radians() / 2.0).tan() * f64::from(h) / f64::from(w))
                .atan()
                .to_degrees()
        };
        r.model.camera = Some(CameraSpec {
            eye: c.eye,
            dir: c.dir,
            up: c.up,
            right: c.right,
            vfov_degrees: vfov,
            width: w,
            height: h,
        });
    }
    let mut model = r.model;
    model.notes.splice(0..0, r.cx.notes);
    Ok(model)
}

impl Reader<'_> {
    fn file(&mut self, bytes: &[u8], path: &Path) -> Result<(), SceneError> {
        let toks = lexer::tokens(bytes, path)?;
        let mut i = 0;
        while i < toks.len() {
            let Token { tok, line } = &toks[i];
            let line = *line;
            let Tok::Word(word) = tok else {
                return Err(SceneError::new(
                    path,
                    line,
                    "(syntax)",
                    format!("expected a directive, found {tok:?}"),
                ));
            };
            i += 1;
            self.directive(word, &toks, &mut i, path, line)?;
        }
        Ok(())
    }

    /// `n` numbers after a directive.
    fn numbers(
        toks: &[Token],
        i: &mut usize,
        n: usize,
        path: &Path,
        word: &str,
        line: usize,
    ) -> Result<Vec<f64>, SceneError> {
        let bracket = matches!(toks.get(*i), Some(Token { tok: Tok::Open, .. }));
        if bracket {
            *i += 1;
        }
        let mut v = Vec::with_capacity(n);
        for _ in 0..n {
            match toks.get(*i) {
                Some(Token {
                    tok: Tok::Num(x), ..
                }) => v.push(*x),
                _ => {
                    return Err(SceneError::new(
                        path,
                        line,
                        word,
                        format!("{word} takes {n} numbers"),
                    ))
                }
            }
            *i += 1;
        }
        if bracket {
            match toks.get(*i) {
                Some(Token {
                    tok: Tok::Close, ..
                }) => *i += 1,
                _ => {
                    return Err(SceneError::new(
                        path,
                        line,
                        word,
                        format!("{word} takes {n} numbers in [ ]"),
                    ))
                }
            }
        }
        Ok(v)
    }

    fn quoted(
        toks: &[Token],
        i: &mut usize,
        path: &Path,
        word: &str,
        line: usize,
    ) -> Result<String, SceneError> {
        match toks.get(*i) {
            Some(Token {
                tok: Tok::Str(s), ..
            }) => {
                *i += 1;
                Ok(s.clone())
            }
            _ => Err(SceneError::new(
                path,
                line,
                word,
                format!("{word} takes a quoted name"),
            )),
        }
    }

    /// A transform directive (Identity, Translate, Scale, Rotate, LookAt,
    /// Transform, ConcatTransform); false for any other word.
    fn transform(
        &mut self,
        word: &str,
        toks: &[Token],
        i: &mut usize,
        path: &Path,
        line: usize,
    ) -> Result<bool, SceneError> {
        let nums = |i: &mut usize, n| Self::numbers(toks, i, n, path, word, line);
        match word {
            "Identity" => self.state.ctm = DMat4::IDENTITY,
            "Translate" => {
                let v = nums(i, 3)?;
                self.state.ctm *= DMat4::from_translation(DVec3::new(v[0], v[1], v[2]));
            }
            "Scale" => {
                let v = nums(i, 3)?;
                self.state.ctm *= DMat4::from_scale(DVec3::new(v[0], v[1], v[2]));
            }
            "Rotate" => {
                let v = nums(i, 4)?;
                let axis = DVec3::new(v[1], v[2], v[3]);
                if axis.length() == 0.0 {
                    return Err(SceneError::new(path, line, word, "the axis is zero".into()));
                }
                self.state.ctm *= DMat4::from_axis_angle(axis.normalize(), v[0].to_radians());
            }
            "LookAt" => {
                let v = nums(i, 9)?;
                self.state.ctm *=
                    objects::look_at(&v).map_err(|m| SceneError::new(path, line, word, m))?;
            }
            "Transform" | "ConcatTransform" => {
                let v = nums(i, 16)?;
                let m = DMat4::from_cols_array(&v.try_into().expect("16 numbers"));
                if m.determinant() == 0.0 || !m.is_finite() {
                    return Err(SceneError::new(
                        path,
                        line,
                        word,
                        "the matrix is singular".into(),
                    ));
                }
                self.state.ctm = if word == "Transform" {
                    m
                } else {
                    self.state.ctm * m
                };
            }
            _ => return Ok(false),
        }
        Ok(true)
    }

    fn directive(
        &mut self,
        word: &str,
        toks: &[Token],
        i: &mut usize,
        path: &Path,
        line: usize,
    ) -> Result<(), SceneError> {
        if self.transform(word, toks, i, path, line)? {
            return Ok(());
        }
        let nums = |i: &mut usize, n| Self::numbers(toks, i, n, path, word, line);
        match word {
            "CoordinateSystem" => {
                let name = Self::quoted(toks, i, path, word, line)?;
                self.coordinate_systems.insert(name, self.state.ctm);
            }
            "CoordSysTransform" => {
                let name = Self::quoted(toks, i, path, word, line)?;
                self.state.ctm = *self.coordinate_systems.get(&name).ok_or_else(|| {
                    SceneError::new(path, line, word, format!("no coordinate system \"{name}\""))
                })?;
            }
            "ReverseOrientation" => self.state.reverse = !self.state.reverse,
            "AttributeBegin" => self.stack.push(self.state.clone()),
            "AttributeEnd" => {
                self.state = self.stack.pop().ok_or_else(|| {
                    SceneError::new(
                        path,
                        line,
                        word,
                        "AttributeEnd without AttributeBegin".into(),
                    )
                })?;
            }
            "TransformBegin" => self.transforms.push(self.state.ctm),
            "TransformEnd" => {
                self.state.ctm = self.transforms.pop().ok_or_else(|| {
                    SceneError::new(
                        path,
                        line,
                        word,
                        "TransformEnd without TransformBegin".into(),
                    )
                })?;
            }
            "WorldBegin" => {
                self.state.ctm = DMat4::IDENTITY;
                self.coordinate_systems
                    .insert("world".into(), DMat4::IDENTITY);
            }
            "WorldEnd" | "TransformTimes" | "ActiveTransform" => {
                if word == "TransformTimes" {
                    nums(i, 2)?;
                } else if word == "ActiveTransform" {
                    *i += 1;
                }
            }
            "Include" | "Import" => self.include(toks, i, path, word, line)?,
            "ObjectBegin" => {
                let name = Self::quoted(toks, i, path, word, line)?;
                if self.defining.is_some() {
                    return Err(SceneError::new(
                        path,
                        line,
                        word,
                        "ObjectBegin inside another object".into(),
                    ));
                }
                self.stack.push(self.state.clone());
                self.defining = Some((name, Vec::new()));
            }
            "ObjectEnd" => {
                let (name, shapes) = self.defining.take().ok_or_else(|| {
                    SceneError::new(path, line, word, "ObjectEnd without ObjectBegin".into())
                })?;
                self.objects.insert(name, shapes);
                self.state = self.stack.pop().unwrap_or_else(|| self.state.clone());
            }
            "ObjectInstance" => {
                let name = Self::quoted(toks, i, path, word, line)?;
                let shapes = self.objects.get(&name).cloned().ok_or_else(|| {
                    SceneError::new(path, line, word, format!("no object \"{name}\""))
                })?;
                let xf = Xf(self.state.ctm);
                for s in shapes {
                    self.shape(&s, &xf)?;
                }
            }
            _ => return self.with_params(word, toks, i, path, line),
        }
        Ok(())
    }

    fn include(
        &mut self,
        toks: &[Token],
        i: &mut usize,
        path: &Path,
        word: &str,
        line: usize,
    ) -> Result<(), SceneError> {
        let name = Self::quoted(toks, i, path, word, line)?;
        if self.depth >= MAX_INCLUDE_DEPTH {
            return Err(SceneError::new(
                path,
                line,
                word,
                format!("includes nest deeper than {MAX_INCLUDE_DEPTH}"),
            ));
        }
        let (file, bytes) = self
            .cx
            .read(&self.dir, &name)
            .map_err(|m| SceneError::new(path, line, word, m))?;
        self.depth += 1;
        let r = self.file(&bytes, &file);
        self.depth -= 1;
        r
    }

    /// A directive with a type and a parameter list.
    fn with_params(
        &mut self,
        word: &str,
        toks: &[Token],
        i: &mut usize,
        path: &Path,
        line: usize,
    ) -> Result<(), SceneError> {
        const TYPED: &[&str] = &[
            "Camera",
            "Film",
            "Sampler",
            "Integrator",
            "PixelFilter",
            "Accelerator",
            "ColorSpace",
            "Option",
            "Shape",
            "Material",
            "MakeNamedMaterial",
            "NamedMaterial",
            "AreaLightSource",
            "LightSource",
            "Texture",
            "MakeNamedMedium",
            "MediumInterface",
            "Attribute",
        ];
        if !TYPED.contains(&word) {
            return Err(SceneError::new(
                path,
                line,
                word,
                format!("unknown directive `{word}`"),
            ));
        }
        let kind = Self::quoted(toks, i, path, word, line)?;
        if word == "Texture" {
            // Texture "name" "type" "class" params
            Self::quoted(toks, i, path, word, line)?;
            Self::quoted(toks, i, path, word, line)?;
        }
        if word == "MediumInterface" {
            // an optional second medium: a quoted name that is not "type name"
            if let Some(Token {
                tok: Tok::Str(s), ..
            }) = toks.get(*i)
            {
                if s.split_whitespace().count() != 2 {
                    *i += 1;
                }
            }
        }
        let list = lexer::params(toks, i, path)?;
        if word == "Shape" {
            let s = PendingShape {
                kind,
                params: list,
                file: path.to_path_buf(),
                line,
                state: self.state.clone(),
            };
            match &mut self.defining {
                Some((_, shapes)) => shapes.push(s),
                None => self.shape(&s, &Xf::IDENTITY)?,
            }
            return Ok(());
        }
        let p = Params::new(list, path, format!("{word} \"{kind}\""), line);
        self.typed(word, &kind, &p)?;
        p.finish()
    }

    fn typed(&mut self, word: &str, kind: &str, p: &Params) -> Result<(), SceneError> {
        let line = p.line;
        match word {
            "Camera" => {
                let camera_from_world = self.state.ctm;
                self.coordinate_systems
                    .insert("camera".into(), camera_from_world.inverse());
                objects::camera(self, kind, p, camera_from_world)?;
            }
            "Film" => objects::film(self, kind, p)?,
            "Sampler" => {
                let spp = p.int("pixelsamples", 16)?;
                p.ignore(&[
                    "seed",
                    "dimension",
                    "randomization",
                    "jitter",
                    "xsamples",
                    "ysamples",
                ]);
                self.spp = Some(spp.clamp(1, 1 << 20) as u32);
            }
            "Integrator" => objects::integrator(self, kind, p)?,
            "PixelFilter" | "Accelerator" | "ColorSpace" | "Option" => {
                p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>())
            }
            "Material" => {
                self.state.material =
                    objects::material(self, kind, p)?.map(|m| (kind.to_string(), m));
            }
            "MakeNamedMaterial" => {
                let ty = p.string("type")?.ok_or_else(|| {
                    p.err(
                        line,
                        "type",
                        "MakeNamedMaterial needs \"string type\"".into(),
                    )
                })?;
                let m = objects::material(self, &ty, p)?;
                self.named
                    .insert(kind.to_string(), m.map(|m| (kind.to_string(), m)));
            }
            "NamedMaterial" => {
                self.state.material = self
                    .named
                    .get(kind)
                    .cloned()
                    .ok_or_else(|| p.err(line, "", format!("no material named \"{kind}\"")))?;
            }
            "AreaLightSource" => self.state.area = Some(objects::area_light(self, kind, p)?),
            "LightSource" => objects::light(self, kind, p)?,
            "Texture" => {
                p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
                self.cx.unsupported(
                    p.file,
                    line,
                    "Texture",
                    "ignored; materials that use it get a constant colour",
                )?;
            }
            "MakeNamedMedium" | "MediumInterface" => {
                p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
                self.cx.unsupported(
                    p.file,
                    line,
                    &format!("{word} (participating media)"),
                    "ignored: the scene is rendered in vacuum",
                )?;
            }
            _ => {
                p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
                self.cx.unsupported(p.file, line, word, "ignored")?;
            }
        }
        Ok(())
    }

    fn shape(&mut self, s: &PendingShape, extra: &Xf) -> Result<(), SceneError> {
        let p = Params::new(
            s.params.clone(),
            &s.file,
            format!("Shape \"{}\"", s.kind),
            s.line,
        );
        objects::shape(self, s, &p, extra)?;
        p.finish()
    }
}
