//! Scenes loaded by name: an embedded scene, or a scene argument that is a
//! file if one exists and an embedded scene's name otherwise.

use std::path::Path;

use crate::scene::import::{self, ImportOptions};
use crate::scene::{load_scene_str, Scene, SceneError};

use super::files::{names, source};

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
/// the path errors and OBJ files are relative to. A `.pbrt` or `.xml` file
/// is converted (`scene::import`, strictly: see `import_text_for`).
pub fn text_for(arg: &Path) -> Result<(String, std::path::PathBuf), SceneError> {
    import_text_for(arg, &ImportOptions::default()).map(|(text, path, _)| (text, path))
}

/// As `text_for`, converting a pbrt or Mitsuba file with `opts`; also
/// returns the conversion's notes. Errors the TOML loader finds in a
/// converted scene name it `<file> as TOML` (`convert-scene` writes that text).
pub fn import_text_for(
    arg: &Path,
    opts: &ImportOptions,
) -> Result<(String, std::path::PathBuf, Vec<String>), SceneError> {
    if import::format_of(arg).is_some() {
        let c = import::convert_file(arg, opts)?;
        let path = std::path::PathBuf::from(format!("{} as TOML", arg.display()));
        return Ok((c.toml, path, c.notes));
    }
    let given = arg.to_string_lossy();
    let name = given.strip_prefix("scenes/").unwrap_or(&given);
    if !arg.exists() {
        if let Some(text) = source(name) {
            let file = format!("scenes/{}.toml", name.trim_end_matches(".toml"));
            return Ok((text.to_string(), file.into(), Vec::new()));
        }
    }
    let text = crate::scene::file::read_stable(arg).map_err(|e| {
        SceneError::new(arg, 0, "(file)", format!("cannot read the scene file: {e}"))
    })?;
    Ok((text, arg.to_path_buf(), Vec::new()))
}

/// A scene argument loaded with `--set` overrides; also returns its text.
pub fn load_with_overrides(
    arg: &Path,
    overrides: &[(String, String)],
) -> Result<(Scene, String), SceneError> {
    load_imported(arg, overrides, &ImportOptions::default()).map(|(scene, text, _)| (scene, text))
}

/// As `load_with_overrides`, converting a pbrt or Mitsuba file with `opts`;
/// also returns the conversion's notes.
pub fn load_imported(
    arg: &Path,
    overrides: &[(String, String)],
    opts: &ImportOptions,
) -> Result<(Scene, String, Vec<String>), SceneError> {
    let (text, path, notes) = import_text_for(arg, opts)?;
    let scene = crate::scene::load_scene_str_with_overrides(&text, &path, overrides)?;
    Ok((scene, text, notes))
}

#[cfg(test)]
mod tests {
    use super::super::files::TEST_SCENES;
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
