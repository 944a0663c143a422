//! The scenes of scenes/, compiled into the binary: `photonmap render ring`
//! renders a paper scene by name from any folder, `photonmap scenes` lists
//! them, and the stress suite and `tables` never look for the source tree.
//! The test scenes of scenes/tests/ are compiled in too and load by name
//! (`tests/furnace` or `tests/furnace.toml`), but are not listed: they are
//! fixtures of the tests and the stress suite, not scenes to render.

mod by_name;
mod files;

pub use by_name::{
    import_text_for, load, load_imported, load_path_or_name, load_with_overrides, text_for,
};
pub use files::{file, names, source, PAPER_SCENES};
