//! The scenes of scenes/, compiled into the binary: `photonmap render ring`
//! renders a paper scene by name from any folder, `photonmap scenes` lists
//! them, and the stress suite and `tables` never look for the source tree.
//! The test scenes of scenes/tests/ are compiled in too and load by name
//! (`tests/furnace` or `tests/furnace.toml`), but are not listed: they are
//! fixtures of the tests and the stress suite, not scenes to render.

use std::path::Path;

use super::{load_scene_str, Scene, SceneError};

include!(concat!(env!("OUT_DIR"), "/scene_sources.rs"));

/// The three scenes of the paper, by the names they are embedded under.
pub const PAPER_SCENES: [&str; 3] = ["glass_ball", "ring", "cornell_box"];

/// The folder under scenes/ whose scenes are the tests' (`tests/<name>`).
const TEST_SCENES: &str = "tests/";

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

/// An embedded scene by name; errors name it as `scenes/<name>.toml`.
pub fn load(name: &str) -> Result<Scene, SceneError> {
    let file = format!("scenes/{}.toml", name.trim_end_matches(".toml"));
    match source(name) {
        Some(text) => load_scene_str(text, Path::new(&file)),
        None => Err(SceneError::new(
            Path::new(&file),
            0,
            "(file)",
            format!(
                "no such embedded scene (embedded: {})",
                names().collect::<Vec<_>>().join(", ")
            ),
        )),
    }
}

/// A scene file, or, when no file of that name exists, the embedded scene of
/// that name (`ring`, `scenes/ring.toml` and `variants/furnace_64_bounces` all
/// work from any folder).
pub fn load_path_or_name(arg: &Path) -> Result<Scene, SceneError> {
    load_with_overrides(arg, &[]).map(|(scene, _)| scene)
}

/// The TOML text a scene argument names (a file, else an embedded scene) and
/// the path errors and OBJ files are relative to.
pub fn text_for(arg: &Path) -> Result<(String, std::path::PathBuf), SceneError> {
    let given = arg.to_string_lossy();
    let name = given.strip_prefix("scenes/").unwrap_or(&given);
    if !arg.exists() {
        if let Some(text) = source(name) {
            let file = format!("scenes/{}.toml", name.trim_end_matches(".toml"));
            return Ok((text.to_string(), file.into()));
        }
    }
    let text = super::file::read_stable(arg).map_err(|e| {
        SceneError::new(arg, 0, "(file)", format!("cannot read the scene file: {e}"))
    })?;
    Ok((text, arg.to_path_buf()))
}

/// A scene argument loaded with `--set` overrides; also returns its text.
pub fn load_with_overrides(
    arg: &Path,
    overrides: &[(String, String)],
) -> Result<(Scene, String), SceneError> {
    let (text, path) = text_for(arg)?;
    let scene = super::load_scene_str_with_overrides(&text, &path, overrides)?;
    Ok((scene, text))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn test_scenes_load_by_name_but_are_not_listed() {
        let fixture = "tests/one_sphere";
        assert!(source(fixture).is_some());
        assert_eq!(source("tests/one_sphere.toml"), source(fixture));
        assert_eq!(load(fixture).unwrap().name, "t");
        let listed: Vec<&str> = names().collect();
        assert!(
            listed.iter().all(|n| !n.starts_with(TEST_SCENES)),
            "{listed:?}"
        );
        assert!(listed.contains(&"glass_ball"), "{listed:?}");
    }
}
