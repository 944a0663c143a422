//! The Mitsuba reader's state (a leaf: the document in `document.rs` and
//! the objects in `objects.rs` both use it).

use std::collections::HashMap;
use std::path::PathBuf;

use roxmltree::Node;

use super::super::model::{Mat, Model};
use super::super::source::{dir_of, Cx};
use super::values::At;
use crate::error::SceneError;

pub struct Reader<'a> {
    pub cx: Cx<'a>,
    pub model: Model,
    /// BSDFs by id, as the materials they became.
    pub bsdfs: HashMap<String, Mat>,
    pub defines: HashMap<String, String>,
    pub depth: usize,
}

impl Reader<'_> {
    /// A file the node names, relative to the folder of the file it is in.
    pub fn read(&self, at: &At, n: Node, name: &str) -> Result<(PathBuf, Vec<u8>), SceneError> {
        self.cx
            .read(&dir_of(at.file), name)
            .map_err(|m| at.err(n, "filename", m))
    }
}
