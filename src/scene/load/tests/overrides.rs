//! `--set` overrides: they change the scene, are validated like the file,
//! and every error about one names it as its file.

use std::path::Path;

use super::cornell::{cornell_text, replace_line};
use super::good;
use crate::scene::{load_scene_str_with_overrides, Geometry, Light, Material, Scene, SceneError};

fn with_overrides(text: &str, sets: &[(&str, &str)]) -> Result<Scene, SceneError> {
    let sets: Vec<(String, String)> = sets
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    load_scene_str_with_overrides(text, Path::new("scenes/cornell_box.toml"), &sets)
}

#[test]
fn overrides_change_the_scene() {
    let text = cornell_text();
    let s = with_overrides(
        &text,
        &[
            ("photon_map.k", "64"),
            ("camera.width", "256"),
            ("shape[6].radius", "0.5"),
            ("materials.glass", "{ type = \"glass\", ior = 1.25 }"),
            (
                "light[2]",
                "{ type = \"point\", position = [0.0, 1.0, 0.0], intensity = [2.0, 2.0, 2.0] }",
            ),
        ],
    )
    .unwrap();
    assert_eq!(
        (s.photon_map.k, s.camera.width, s.camera.height),
        (64, 256, 512)
    );
    assert!(matches!(s.shapes[6].geometry, Geometry::Sphere { radius, .. } if radius == 0.5));
    assert_eq!(
        s.materials[s.shapes[6].material],
        Material::Glass { ior: 1.25 }
    );
    assert_eq!(s.lights.len(), 3);
    assert!(matches!(s.lights[2], Light::Point { intensity, .. } if intensity.x == 2.0));
    // A table the file does not have is created.
    let s = with_overrides(
        good(),
        &[("render.shadow_rays", "8"), ("photon_map.k", "7")],
    )
    .unwrap();
    assert_eq!((s.render.shadow_rays, s.photon_map.k), (8, 7));
    // Later overrides win.
    let s = with_overrides(good(), &[("photon_map.k", "7"), ("photon_map.k", "9")]).unwrap();
    assert_eq!(s.photon_map.k, 9);
}

#[test]
fn overrides_are_validated_like_the_file_and_errors_name_them() {
    let text = cornell_text();
    for (key, value, field, says) in [
        ("shape[6].radius", "-1", "shape[6].radius", "greater than 0"),
        (
            "shape[6].radiu",
            "1",
            "radiu",
            "unknown field `radiu` in shape[6]",
        ),
        ("camera.vfov", "\"wide\"", "vfov", "expected f32"),
        (
            "photon_map.projection_resolution",
            "1000",
            "photon_map.projection_resolution",
            "4..=128",
        ),
        (
            "shape[6].type",
            "\"cone\"",
            "type",
            "unknown variant `cone`",
        ),
        (
            "shape[6].material",
            "\"gold\"",
            "shape[6].material",
            "no material named \"gold\"",
        ),
        (
            "shape[9].radius",
            "1",
            "shape[9].radius",
            "`shape` has 7 entries",
        ),
        ("camera.position.x", "1", "camera.position.x", "not a table"),
        ("photon_map.k", "6 4", "photon_map.k", "not a TOML value"),
        ("shape[x].radius", "1", "shape[x].radius", "not a key path"),
    ] {
        let e = with_overrides(&text, &[(key, value)]).unwrap_err();
        assert_eq!(e.file, Path::new(&format!("--set {key}")), "{e}");
        assert_eq!((e.line, e.field.as_str()), (1, field), "{e}");
        assert!(e.message.contains(says), "{e}");
        assert!(
            e.to_string()
                .starts_with(&format!("--set {key}:1: {field}: ")),
            "{e}"
        );
    }
    // An error in the file is still the file's, overrides or not.
    let (broken, line, _) = replace_line(&text, "[[shape]]", 6, "radius", "radiu = 0.35");
    let e = with_overrides(&broken, &[("photon_map.k", "64")]).unwrap_err();
    assert_eq!(
        (e.file.as_path(), e.line),
        (Path::new("scenes/cornell_box.toml"), line)
    );
    // Changing a shape's type leaves the file's fields of the old type unknown,
    // at their own lines in the file.
    let e = with_overrides(&text, &[("shape[6].type", "\"cylinder\"")]).unwrap_err();
    let (_, center, _) = replace_line(&text, "[[shape]]", 6, "center", "center = [0.0, 0.0, 0.0]");
    assert_eq!(
        (e.file.as_path(), e.line, e.field.as_str()),
        (Path::new("scenes/cornell_box.toml"), center, "center"),
        "{e}"
    );
    // A whole table from an override: its missing fields are the override's.
    let e = with_overrides(
        &text,
        &[(
            "shape[6]",
            "{ type = \"sphere\", center = [0.0, 0.5, 0.0], material = \"glass\" }",
        )],
    )
    .unwrap_err();
    assert_eq!(
        (e.file.as_path(), e.line, e.field.as_str()),
        (Path::new("--set shape[6]"), 1, "radius"),
        "{e}"
    );
    assert!(
        e.message.contains("missing field `radius` in shape[6]"),
        "{e}"
    );
}
