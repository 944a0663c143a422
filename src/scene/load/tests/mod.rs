//! The loader's tests, none of which needs a GPU: each malformed scene's
//! error (`errors.rs`, in the Cornell box `cornell.rs`, through `--set`
//! `overrides.rs`), the pinned numbers and defaults (`defaults.rs`), OBJ
//! meshes and MTL materials (`meshes.rs`), scenes far from the origin
//! (`rebase.rs`) and mutation fuzzing (`fuzz.rs`).

use std::path::PathBuf;

use crate::scene::{embedded, load_scene, Scene};

mod cornell;
mod defaults;
mod errors;
mod fuzz;
mod meshes;
mod overrides;
mod rebase;

/// The source tree's root, where scenes/, tests/ and README.md are.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A scene of scenes/, loaded from its file.
fn paper_scene(name: &str) -> Scene {
    load_scene(&root().join("scenes").join(format!("{name}.toml"))).expect("paper scene loads")
}

/// The text of a test scene of scenes/tests/, by the name it is embedded
/// under (`tests/<name>`).
fn fixture(name: &str) -> &'static str {
    embedded::source(&format!("tests/{name}"))
        .unwrap_or_else(|| panic!("scenes/tests/{name}.toml is not embedded"))
}

/// A temporary folder holding one file, `name`, of `text` (a mesh the test's
/// scene names).
fn dir_with(name: &str, text: &str) -> tempfile::TempDir {
    let temp = tempfile::tempdir().unwrap();
    std::fs::write(temp.path().join(name), text).unwrap();
    temp
}

/// The good scene every malformed one in these tests is made from: one
/// sphere and one point light.
fn good() -> &'static str {
    fixture("one_sphere")
}
