//! The files of scenes/ as compiled in: the scenes by name, and the files
//! (OBJ, MTL) they refer to by path.

use std::path::Path;

include!(concat!(env!("OUT_DIR"), "/scene_sources.rs"));

/// The three scenes of the paper, by the names they are embedded under.
pub const PAPER_SCENES: [&str; 3] = ["glass_ball", "ring", "cornell_box"];

/// The folder under scenes/ whose scenes are the tests' (`tests/<name>`).
pub(super) const TEST_SCENES: &str = "tests/";

/// Names of the embedded scenes (paths under scenes/ without `.toml`), in
/// order: `glass_ball`, `variants/furnace_64_bounces`, ...; not the test
/// scenes of scenes/tests/.
pub fn names() -> impl Iterator<Item = &'static str> {
    SCENE_SOURCES
        .iter()
        // Camera paths live beside the scenes but are not scenes.
        .filter(|(path, text)| path.ends_with(".toml") && text.contains("[camera]"))
        .filter(|(path, _)| !path.starts_with(TEST_SCENES))
        .map(|(path, _)| path.trim_end_matches(".toml"))
}

/// The TOML text of an embedded scene.
pub fn source(name: &str) -> Option<&'static str> {
    let file = format!("{}.toml", name.trim_end_matches(".toml"));
    SCENE_SOURCES
        .iter()
        .find(|(path, _)| *path == file)
        .map(|(_, text)| *text)
}

/// The embedded copy of a file a scene refers to (an OBJ or MTL file), by
/// its path as the loader forms it: `scenes/` then the path under scenes/
/// (`scenes/cornell_box_obj/cornell_box.obj`; `.` and `..` are resolved).
pub fn file(path: &Path) -> Option<&'static str> {
    let mut parts: Vec<String> = Vec::new();
    for c in path.components() {
        match c {
            std::path::Component::Normal(s) => parts.push(s.to_string_lossy().into_owned()),
            std::path::Component::ParentDir => {
                parts.pop()?;
            }
            std::path::Component::CurDir => {}
            _ => return None,
        }
    }
    let rest = parts.strip_prefix(&["scenes".to_string()])?.join("/");
    SCENE_SOURCES
        .iter()
        .find(|(p, _)| *p == rest)
        .map(|(_, text)| *text)
}
