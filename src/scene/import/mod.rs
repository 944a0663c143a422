//! Scenes in other renderers' formats: pbrt-v4 (`.pbrt`, `pbrt/`) and
//! Mitsuba 3 XML (`.xml`, `mitsuba/`), with PLY meshes (`ply.rs`). Each is
//! read into a `Model` (`model.rs`: world-space surfaces, materials and
//! lights as photonmap renders them) and written as the TOML scene photonmap
//! understood (`model::to_toml`), which the TOML loader then reads like any
//! scene file, `--set` overrides included. What photonmap cannot render is
//! refused with the file, line and what it is, unless `lenient` is set,
//! when it is mapped to the nearest thing it can, with one note each.
//!
//! The parsers take bytes (`convert_bytes`), and read the files a scene
//! names (includes, meshes) through `Files`, so tests and the fuzz replay
//! run them on bytes alone.

mod convert;
pub mod geometry;
pub mod mitsuba;
pub mod model;
pub mod pbrt;
pub mod ply;
mod source;
#[cfg(test)]
mod tests;

pub use convert::{convert_bytes, convert_file};
pub use source::{dir_of, format_of, Converted, Cx, Disk, Files, Format, ImportOptions, NoFiles};
