//! Every error at its own line, in a real scene: typos and missing fields
//! in scenes/cornell_box.toml.

use std::path::Path;

use super::root;
use crate::scene::load_scene_str;

/// scenes/cornell_box.toml with a second light, a point light (so that
/// `light[1]` exists), appended.
pub(super) fn cornell_text() -> String {
    std::fs::read_to_string(root().join("scenes/cornell_box.toml")).unwrap()
        + "\n[[light]]\ntype = \"point\"\nposition = [0.0, 1.5, 0.0]\nintensity = [1.0, 1.0, 1.0]\n"
}

/// `text` with the first line starting with `key` after the `index`th
/// (0-based) line starting with `header` replaced by `with` (removed when
/// `with` is empty); returns the new text, the 1-based number of the line
/// replaced and that of the header.
pub(super) fn replace_line(
    text: &str,
    header: &str,
    index: usize,
    key: &str,
    with: &str,
) -> (String, usize, usize) {
    let mut lines: Vec<&str> = text.lines().collect();
    let header_at = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| l.starts_with(header))
        .nth(index)
        .unwrap_or_else(|| panic!("no {header} number {index}"))
        .0;
    let at = (header_at + 1..lines.len())
        .find(|&i| lines[i].starts_with(key))
        .unwrap_or_else(|| panic!("no {key} after {header} number {index}"));
    if with.is_empty() {
        lines.remove(at);
    } else {
        lines[at] = with;
    }
    (lines.join("\n") + "\n", at + 1, header_at + 1)
}

/// One typo in the Cornell box: where it goes, and what the error must say.
struct Typo {
    header: &'static str,
    index: usize,
    key: &'static str,
    with: &'static str,
    /// Lines from the replaced line to the error's (an element further down).
    below: usize,
    field: &'static str,
    says: &'static [&'static str],
}

const TYPOS: &[Typo] = &[
    // Unknown fields, at the unknown key's line.
    Typo {
        header: "[[shape]]",
        index: 6,
        key: "radius",
        with: "radiu = 0.35",
        below: 0,
        field: "radiu",
        says: &["unknown field `radiu` in shape[6]"],
    },
    Typo {
        header: "[[shape]]",
        index: 0,
        key: "edge1",
        with: "edge = [0.0, 0.0, 2.0]",
        below: 0,
        field: "edge",
        says: &["unknown field `edge` in shape[0]"],
    },
    Typo {
        header: "[[shape]]",
        index: 4,
        key: "material",
        with: "materia = \"blue\"",
        below: 0,
        field: "materia",
        says: &["unknown field `materia` in shape[4]"],
    },
    Typo {
        header: "[materials]",
        index: 0,
        key: "red",
        with: "red = { type = \"diffuse\", albedo = [0.75, 0.25, 0.25], albdo = 1 }",
        below: 0,
        field: "albdo",
        says: &["unknown field `albdo` in materials.red"],
    },
    Typo {
        header: "[[light]]",
        index: 0,
        key: "normal",
        with: "normall = [0.0, -1.0, 0.0]",
        below: 0,
        field: "normall",
        says: &["unknown field `normall` in light[0]"],
    },
    Typo {
        header: "[[light]]",
        index: 1,
        key: "position",
        with: "positon = [0.0, 1.5, 0.0]",
        below: 0,
        field: "positon",
        says: &["unknown field `positon` in light[1]"],
    },
    Typo {
        header: "[camera]",
        index: 0,
        key: "vfov",
        with: "fov = 40.0",
        below: 0,
        field: "fov",
        says: &["unknown field `fov` in camera"],
    },
    Typo {
        header: "[photon_map]",
        index: 0,
        key: "k =",
        with: "kk = 500",
        below: 0,
        field: "kk",
        says: &["unknown field `kk` in photon_map"],
    },
    // Wrong types, at the value's line (the element's, inside an array).
    Typo {
        header: "[[shape]]",
        index: 6,
        key: "radius",
        with: "radius = \"big\"",
        below: 0,
        field: "radius",
        says: &["expected f32", "shape[6].radius"],
    },
    Typo {
        header: "[[shape]]",
        index: 3,
        key: "material",
        with: "material = 5",
        below: 0,
        field: "material",
        says: &["expected a string", "shape[3].material"],
    },
    Typo {
        header: "[[shape]]",
        index: 4,
        key: "corner",
        with: "corner = [1.0, 0.0]",
        below: 0,
        field: "corner",
        says: &["invalid length 2", "shape[4].corner"],
    },
    Typo {
        header: "[[shape]]",
        index: 2,
        key: "edge2",
        with: "edge2 = [\n  0.0,\n  2.0,\n  \"z\",\n]",
        below: 3,
        field: "edge2",
        says: &["expected f32", "shape[2].edge2"],
    },
    Typo {
        header: "[materials]",
        index: 0,
        key: "glass",
        with: "glass = { type = \"glass\", ior = \"1.5\" }",
        below: 0,
        field: "ior",
        says: &["expected f32", "materials.glass.ior"],
    },
    Typo {
        header: "[[light]]",
        index: 0,
        key: "radiance",
        with: "radiance = 25.0",
        below: 0,
        field: "radiance",
        says: &["expected an array", "light[0].radiance"],
    },
    Typo {
        header: "[[light]]",
        index: 1,
        key: "intensity",
        with: "intensity = \"bright\"",
        below: 0,
        field: "intensity",
        says: &["light[1].intensity"],
    },
    Typo {
        header: "[render]",
        index: 0,
        key: "shadow_rays",
        with: "shadow_rays = 1.5",
        below: 0,
        field: "shadow_rays",
        says: &["expected i64", "render.shadow_rays"],
    },
    // Unknown types, at the `type` line (inline tables: the material's line).
    Typo {
        header: "[[shape]]",
        index: 5,
        key: "type",
        with: "type = \"spere\"",
        below: 0,
        field: "type",
        says: &["unknown variant `spere`", "shape[5].type"],
    },
    Typo {
        header: "[materials]",
        index: 0,
        key: "mirror",
        with: "mirror = { type = \"mirorr\", reflectance = [0.95, 0.95, 0.95] }",
        below: 0,
        field: "type",
        says: &["unknown variant `mirorr`", "materials.mirror.type"],
    },
    Typo {
        header: "[[light]]",
        index: 1,
        key: "type",
        with: "type = \"spot\"",
        below: 0,
        field: "type",
        says: &["unknown variant `spot`", "light[1].type"],
    },
    // Values out of range, at the value's line.
    Typo {
        header: "[[shape]]",
        index: 6,
        key: "radius",
        with: "radius = -0.35",
        below: 0,
        field: "shape[6].radius",
        says: &["greater than 0"],
    },
    Typo {
        header: "[materials]",
        index: 0,
        key: "blue",
        with: "blue = { type = \"diffuse\", albedo = [0.25, 0.25, 1.75] }",
        below: 0,
        field: "materials.blue.albedo",
        says: &["[0, 1]"],
    },
    Typo {
        header: "[[light]]",
        index: 1,
        key: "intensity",
        with: "intensity = [1.0, -1.0, 1.0]",
        below: 0,
        field: "light[1].intensity",
        says: &[">= 0"],
    },
    Typo {
        header: "[photon_map]",
        index: 0,
        key: "k =",
        with: "k = 0",
        below: 0,
        field: "photon_map.k",
        says: &["1..=4096"],
    },
];

#[test]
fn typos_in_the_cornell_box_are_reported_at_their_own_line() {
    let text = cornell_text();
    let path = Path::new("scenes/cornell_box.toml");
    let s = load_scene_str(&text, path).unwrap();
    assert_eq!(s.lights.len(), 2);
    for t in TYPOS {
        let (broken, line, _) = replace_line(&text, t.header, t.index, t.key, t.with);
        let line = line + t.below;
        let e = load_scene_str(&broken, path).expect_err(t.with);
        assert_eq!(
            (e.line, e.field.as_str()),
            (line, t.field),
            "{:?} in {} number {}: {e}",
            t.with,
            t.header,
            t.index
        );
        for says in t.says {
            assert!(e.message.contains(says), "{:?}: {e}", t.with);
        }
        assert!(
            e.to_string()
                .starts_with(&format!("scenes/cornell_box.toml:{line}: {}: ", t.field)),
            "{e}"
        );
    }
}

#[test]
fn missing_fields_in_the_cornell_box_are_reported_at_their_table() {
    let text = cornell_text();
    for (header, index, key, path) in [
        ("[[shape]]", 6, "radius", "shape[6]"),
        ("[[shape]]", 0, "edge2", "shape[0]"),
        ("[[light]]", 0, "radiance", "light[0]"),
        ("[[light]]", 1, "type", "light[1]"),
        ("[camera]", 0, "width", "camera"),
    ] {
        let (broken, _, header_line) = replace_line(&text, header, index, key, "");
        let e = load_scene_str(&broken, Path::new("cb.toml")).unwrap_err();
        assert_eq!((e.line, e.field.as_str()), (header_line, key), "{e}");
        assert!(
            e.message
                .contains(&format!("missing field `{key}` in {path}")),
            "{e}"
        );
    }
    // In an inline table: the table's line.
    let (broken, line, _) = replace_line(
        &text,
        "[materials]",
        0,
        "glass",
        "glass = { type = \"glass\" }",
    );
    let e = load_scene_str(&broken, Path::new("cb.toml")).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (line, "ior"), "{e}");
}
