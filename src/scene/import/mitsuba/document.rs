//! A Mitsuba XML document: parsed by roxmltree (whose text positions give
//! every error its line), `<default>`s and `-D` values, `<include>`d
//! files, BSDFs by `id`, and the scene's children handed to `objects.rs`.

use std::collections::HashMap;
use std::path::Path;

use roxmltree::Node;

use super::super::model::Model;
use super::super::source::{Cx, Files, ImportOptions};
use super::objects;
use super::state::Reader;
use super::values::At;
use crate::error::SceneError;

/// The deepest chain of includes.
const MAX_INCLUDE_DEPTH: usize = 32;

/// Reads a Mitsuba 3 (or 0.6) XML file, and what it includes, into a model.
pub fn read(
    bytes: &[u8],
    path: &Path,
    files: &dyn Files,
    opts: &ImportOptions,
) -> Result<Model, SceneError> {
    let mut r = Reader {
        cx: Cx::new(files, opts),
        model: Model::for_file(path),
        bsdfs: HashMap::new(),
        defines: opts.defines.iter().cloned().collect(),
        depth: 0,
    };
    r.file(bytes, path)?;
    let mut model = r.model;
    model.notes.splice(0..0, r.cx.notes);
    Ok(model)
}

/// The text, or an error at the line of the first byte that is not UTF-8.
fn utf8<'b>(bytes: &'b [u8], path: &Path) -> Result<&'b str, SceneError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = 1 + bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        SceneError::new(path, line, "(xml)", "the file is not UTF-8 text".into())
    })
}

impl Reader<'_> {
    fn file(&mut self, bytes: &[u8], path: &Path) -> Result<(), SceneError> {
        let text = utf8(bytes, path)?;
        let opts = roxmltree::ParsingOptions {
            allow_dtd: true,
            ..Default::default()
        };
        let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| {
            let message = e.to_string();
            let message = message
                .rsplit_once(" at ")
                .map_or(message.as_str(), |(m, _)| m)
                .to_string();
            SceneError::new(path, e.pos().row as usize, "(xml)", message)
        })?;
        let root = doc.root_element();
        let defines = self.defines.clone();
        let at = At {
            file: path,
            doc: &doc,
            defines: &defines,
        };
        if root.tag_name().name() != "scene" {
            return Err(at.err(
                root,
                "(xml)",
                format!(
                    "the root element is <{}>, not <scene>",
                    root.tag_name().name()
                ),
            ));
        }
        for child in root.children().filter(Node::is_element) {
            if child.tag_name().name() == "default" {
                let name = at.req(child, "name")?;
                let value = at.req(child, "value")?;
                self.defines.entry(name).or_insert(value);
                continue;
            }
            let defines = self.defines.clone();
            let at = At {
                file: path,
                doc: &doc,
                defines: &defines,
            };
            self.element(&at, child)?;
        }
        Ok(())
    }

    fn element(&mut self, at: &At, n: Node) -> Result<(), SceneError> {
        match n.tag_name().name() {
            "include" => self.include(at, n),
            "sensor" => objects::sensor(self, at, n),
            "integrator" => objects::integrator(self, at, n),
            "bsdf" => {
                let id = at.req(n, "id")?;
                let m = objects::bsdf(self, at, n)?;
                self.bsdfs.insert(id, m);
                Ok(())
            }
            "shape" => objects::shape(self, at, n),
            "emitter" => objects::emitter(self, at, n),
            "texture" | "spectrum" | "rgb" | "float" | "integer" | "boolean" | "string"
            | "point" | "vector" | "transform" => {
                let what = format!("<{}> at the scene's top level", n.tag_name().name());
                self.cx.unsupported(at.file, at.line(n), &what, "ignored")
            }
            "medium" => self.cx.unsupported(
                at.file,
                at.line(n),
                "<medium> (participating media)",
                "ignored: the scene is rendered in vacuum",
            ),
            other => Err(at.err(n, other, format!("unknown element <{other}>"))),
        }
    }

    fn include(&mut self, at: &At, n: Node) -> Result<(), SceneError> {
        let name = at.req(n, "filename")?;
        if self.depth >= MAX_INCLUDE_DEPTH {
            return Err(at.err(
                n,
                "include",
                format!("includes nest deeper than {MAX_INCLUDE_DEPTH}"),
            ));
        }
        let (file, bytes) = self.read(at, n, &name)?;
        self.depth += 1;
        let r = self.file(&bytes, &file);
        self.depth -= 1;
        r
    }
}
