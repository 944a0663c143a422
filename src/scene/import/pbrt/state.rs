//! The pbrt reader's state: the graphics state AttributeBegin saves, the
//! shapes object definitions keep, and the reader's own (a leaf: the
//! directives in `reader.rs` and the objects in `objects.rs` both use it).

use std::collections::HashMap;
use std::path::PathBuf;

use glam::DMat4;

use super::super::model::{Mat, Model};
use super::super::source::Cx;
use super::lexer;

/// The current AreaLightSource.
#[derive(Clone, Debug)]
pub struct AreaLight {
    pub radiance: [f64; 3],
}

/// The camera as placed: eye, view, up, image right (world), and the fov.
#[derive(Clone, Copy, Debug)]
pub struct PbrtCamera {
    pub eye: glam::DVec3,
    pub dir: glam::DVec3,
    pub up: glam::DVec3,
    pub right: glam::DVec3,
    /// Degrees, across the image's shorter side.
    pub fov: f64,
}

/// The graphics state AttributeBegin saves.
#[derive(Clone)]
pub struct State {
    pub ctm: DMat4,
    pub reverse: bool,
    /// None: `interface`, whose shapes are left out.
    pub material: Option<(String, Mat)>,
    /// The current AreaLightSource: radiance, two-sided, and its line.
    pub area: Option<AreaLight>,
}

/// A shape as its directive left it, placed when emitted (object instances
/// place theirs again under each instance's transform).
#[derive(Clone)]
pub struct PendingShape {
    pub kind: String,
    pub params: Vec<lexer::Param>,
    pub file: PathBuf,
    pub line: usize,
    pub state: State,
}

pub struct Reader<'a> {
    pub cx: Cx<'a>,
    pub model: Model,
    pub state: State,
    pub stack: Vec<State>,
    pub transforms: Vec<DMat4>,
    pub named: HashMap<String, Option<(String, Mat)>>,
    pub coordinate_systems: HashMap<String, DMat4>,
    pub objects: HashMap<String, Vec<PendingShape>>,
    /// The object being defined: its name and shapes.
    pub defining: Option<(String, Vec<PendingShape>)>,
    /// The directory relative paths start from (the main file's, as in pbrt).
    pub dir: PathBuf,
    pub depth: usize,
    /// pixelsamples and whether the integrator is sppm (with its options).
    pub spp: Option<u32>,
    pub camera: Option<PbrtCamera>,
    pub film: (u32, u32),
}

/// The deepest chain of Include/Import.
pub const MAX_INCLUDE_DEPTH: usize = 32;
