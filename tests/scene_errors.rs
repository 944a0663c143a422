//! Each kind of malformed scene gives its own error, naming file, line and field.

mod common;

use std::path::Path;

use photonmap::scene::{load_scene, load_scene_str, SceneError};

const GOOD: &str = r#"name = "t"
[camera]
position = [0.0, 1.0, 3.0]
look_at = [0.0, 0.0, 0.0]
vfov = 40.0
width = 64
height = 48

[materials]
white = { type = "diffuse", albedo = [0.5, 0.5, 0.5] }

[[shape]]
type = "sphere"
center = [0.0, 0.0, 0.0]
radius = 1.0
material = "white"

[[light]]
type = "point"
position = [0.0, 3.0, 0.0]
intensity = [1.0, 1.0, 1.0]
"#;

fn load(text: &str) -> Result<photonmap::scene::Scene, SceneError> {
    load_scene_str(text, Path::new("scenes/broken.toml"))
}

/// Replaces `from` in the good scene and expects an error at `line` on `field`
/// whose message contains `says`.
fn expect(from: &str, to: &str, line: usize, field: &str, says: &str) {
    assert!(GOOD.contains(from), "{from:?} not in the good scene");
    let text = GOOD.replacen(from, to, 1);
    let e = load(&text).expect_err(&format!("{from:?} -> {to:?} should fail"));
    assert_eq!(e.file, Path::new("scenes/broken.toml"));
    assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
    assert!(e.message.contains(says), "{e}");
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("scenes/broken.toml:{line}: {field}: ")),
        "{shown}"
    );
}

#[test]
fn the_good_scene_loads() {
    let s = load(GOOD).unwrap();
    assert_eq!((s.shapes.len(), s.lights.len(), s.camera.width), (1, 1, 64));
}

#[test]
fn syntax_error() {
    expect("vfov = 40.0", "vfov = = 40.0", 5, "vfov", "");
}

#[test]
fn unknown_field() {
    expect("radius = 1.0", "radiu = 1.0", 15, "radiu", "unknown field");
}

#[test]
fn missing_field() {
    expect("radius = 1.0\n", "", 12, "radius", "missing field");
}

#[test]
fn wrong_type() {
    expect(
        "radius = 1.0",
        "radius = \"big\"",
        15,
        "radius",
        "expected f32",
    );
}

#[test]
fn unknown_shape_type() {
    expect(
        "type = \"sphere\"",
        "type = \"cone\"",
        13,
        "type",
        "unknown variant `cone`",
    );
}

#[test]
fn nan_value() {
    expect(
        "radius = 1.0",
        "radius = nan",
        15,
        "shape[0].radius",
        "not a finite number",
    );
}

#[test]
fn negative_radius() {
    expect(
        "radius = 1.0",
        "radius = -1.0",
        15,
        "shape[0].radius",
        "greater than 0",
    );
}

#[test]
fn albedo_above_one() {
    expect(
        "albedo = [0.5, 0.5, 0.5]",
        "albedo = [0.5, 1.5, 0.5]",
        10,
        "materials.white.albedo",
        "[0, 1]",
    );
}

#[test]
fn unknown_material() {
    expect(
        "material = \"white\"",
        "material = \"black\"",
        16,
        "shape[0].material",
        "no material named \"black\"",
    );
}

#[test]
fn absurd_resolution() {
    expect(
        "width = 64",
        "width = 100000",
        6,
        "camera.width",
        "1..=16384",
    );
}

#[test]
fn camera_looking_at_itself() {
    expect(
        "look_at = [0.0, 0.0, 0.0]",
        "look_at = [0.0, 1.0, 3.0]",
        4,
        "camera.look_at",
        "equals camera.position",
    );
}

#[test]
fn negative_light() {
    expect(
        "intensity = [1.0, 1.0, 1.0]",
        "intensity = [1.0, -1.0, 1.0]",
        21,
        "light[0].intensity",
        ">= 0",
    );
}

#[test]
fn no_light() {
    let text = GOOD.split("[[light]]").next().unwrap();
    let e = load(text).unwrap_err();
    assert_eq!(e.field, "light");
    assert!(e.message.contains("no [[light]]"), "{e}");
}

#[test]
fn area_light_normal_off_its_plane() {
    let text = GOOD.replace(
        "type = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]",
        "type = \"area\"\ncorner = [0.0, 3.0, 0.0]\nedge1 = [1.0, 0.0, 0.0]\nedge2 = [0.0, 0.0, 1.0]\nnormal = [1.0, 0.0, 0.0]\nradiance = [1.0, 1.0, 1.0]",
    );
    let e = load(&text).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (23, "light[0].normal"), "{e}");
}

#[test]
fn zero_area_light() {
    let text = GOOD.replace(
        "type = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]",
        "type = \"area\"\ncorner = [0.0, 3.0, 0.0]\nedge1 = [1.0, 0.0, 0.0]\nedge2 = [2.0, 0.0, 0.0]\nradiance = [1.0, 1.0, 1.0]",
    );
    let e = load(&text).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (22, "light[0].edge2"), "{e}");
    assert!(e.message.contains("no area"), "{e}");
}

#[test]
fn non_planar_polygon() {
    let text = GOOD.replace(
        "type = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        "type = \"polygon\"\nvertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]]",
    );
    let e = load(&text).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (14, "shape[0].vertices"), "{e}");
    assert!(e.message.contains("planar"), "{e}");
}

fn with_mesh(dir: &Path, obj_name: &str) -> std::path::PathBuf {
    let text = GOOD.replace(
        "type = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        &format!("type = \"mesh\"\nfile = \"{obj_name}\""),
    );
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn missing_obj_names_the_path() {
    let dir = tempdir("missing_obj");
    let e = load_scene(&with_mesh(&dir, "nowhere.obj")).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (14, "shape[0].file"), "{e}");
    assert!(
        e.message
            .contains(&dir.join("nowhere.obj").display().to_string()),
        "{e}"
    );
}

#[test]
fn obj_with_nan_vertex_is_refused() {
    let dir = tempdir("nan_obj");
    std::fs::write(
        dir.join("bad.obj"),
        "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
    )
    .unwrap();
    let e = load_scene(&with_mesh(&dir, "bad.obj")).unwrap_err();
    assert!(e.message.contains("finite"), "{e}");
}

#[test]
fn good_obj_loads_as_triangles() {
    let dir = tempdir("good_obj");
    std::fs::write(
        dir.join("quad.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let s = load_scene(&with_mesh(&dir, "quad.obj")).unwrap();
    assert_eq!(s.shapes.len(), 2);
}

#[test]
fn missing_scene_file() {
    let e = load_scene(Path::new("/nonexistent/scene.toml")).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("/nonexistent/scene.toml:0: (file): cannot read"),
        "{e}"
    );
}

#[test]
fn the_paper_scenes_match_the_pinned_numbers() {
    use glam::Vec3;
    use photonmap::scene::{Geometry, Light, Material};
    let g = common::paper_scene("glass_ball");
    assert_eq!(
        (g.camera.width, g.camera.height, g.camera.vfov_degrees),
        (512, 384, 38.0)
    );
    assert_eq!(
        (
            g.photon_map.photons_stored,
            g.photon_map.k,
            g.render.shadow_rays
        ),
        (5000, 32, 4)
    );
    assert_eq!(g.photon_map.grid_resolution, [250, 1, 250]);
    assert!(g.shapes.iter().any(|s| s.geometry
        == Geometry::Sphere {
            center: Vec3::new(0.0, 0.8, 0.0),
            radius: 0.8
        }
        && g.materials[s.material] == Material::Glass { ior: 1.5 }));
    assert!(matches!(g.lights[0], Light::Area { radiance, .. } if radiance == Vec3::splat(60.0)));

    let r = common::paper_scene("ring");
    assert_eq!(
        (
            r.photon_map.photons_stored,
            r.photon_map.k,
            r.render.shadow_rays
        ),
        (16000, 64, 1)
    );
    assert_eq!(
        r.lights[0],
        Light::Point {
            position: Vec3::new(0.0, 1.4, -3.2),
            intensity: Vec3::splat(40.0)
        }
    );
    assert!(r.shapes.iter().any(|s| s.geometry
        == Geometry::Cylinder {
            base: Vec3::ZERO,
            axis: Vec3::Y,
            radius: 1.0,
            height: 0.6
        }
        && r.materials[s.material]
            == Material::Mirror {
                reflectance: Vec3::new(0.95, 0.80, 0.45)
            }));

    let c = common::paper_scene("cornell_box");
    assert_eq!((c.camera.width, c.camera.height), (512, 512));
    assert_eq!(
        (
            c.photon_map.photons_stored,
            c.photon_map.k,
            c.render.shadow_rays
        ),
        (65000, 500, 32)
    );
    assert_eq!(c.photon_map.grid_resolution, [25, 25, 50]);
    let power = c.lights[0].power(&c.shapes);
    assert!(
        (power.x - std::f32::consts::PI * 0.25 * 25.0).abs() < 1e-4,
        "{power}"
    );
    assert_eq!(c.shapes.len(), 5 + 2 + 1, "5 walls, 2 spheres, the light");
}

fn tempdir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("photonmap-test-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn caustics_only_without_a_specular_shape() {
    expect(
        "[materials]",
        "[photon_map]\ncaustics_only = true\n\n[materials]",
        10,
        "photon_map.caustics_only",
        "no shape is mirror or glass",
    );
}

#[test]
fn caustics_only_with_store_direct() {
    expect(
        "[materials]",
        "[photon_map]\nstore_direct = true\ncaustics_only = true\n\n[materials]",
        11,
        "photon_map.caustics_only",
        "exclude each other",
    );
}

#[test]
fn projection_resolution_out_of_range() {
    expect(
        "[materials]",
        "[photon_map]\nprojection_resolution = 1000\n\n[materials]",
        10,
        "photon_map.projection_resolution",
        "4..=128",
    );
}

// ---- every error at its own line, in a real scene -------------------------------

/// scenes/cornell_box.toml with a second light, a point light (so that
/// `light[1]` exists), appended.
fn cornell_text() -> String {
    std::fs::read_to_string(common::root().join("scenes/cornell_box.toml")).unwrap()
        + "\n[[light]]\ntype = \"point\"\nposition = [0.0, 1.5, 0.0]\nintensity = [1.0, 1.0, 1.0]\n"
}

/// `text` with the first line starting with `key` after the `index`th
/// (0-based) line starting with `header` replaced by `with` (removed when
/// `with` is empty); returns the new text, the 1-based number of the line
/// replaced and that of the header.
fn replace_line(
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

// ---- overrides --------------------------------------------------------------------------

fn with_overrides(
    text: &str,
    sets: &[(&str, &str)],
) -> Result<photonmap::scene::Scene, SceneError> {
    let sets: Vec<(String, String)> = sets
        .iter()
        .map(|(k, v)| (k.to_string(), v.to_string()))
        .collect();
    photonmap::scene::load_scene_str_with_overrides(
        text,
        Path::new("scenes/cornell_box.toml"),
        &sets,
    )
}

#[test]
fn overrides_change_the_scene() {
    use photonmap::scene::{Geometry, Light, Material};
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
    let s = with_overrides(GOOD, &[("render.shadow_rays", "8"), ("photon_map.k", "7")]).unwrap();
    assert_eq!((s.render.shadow_rays, s.photon_map.k), (8, 7));
    // Later overrides win.
    let s = with_overrides(GOOD, &[("photon_map.k", "7"), ("photon_map.k", "9")]).unwrap();
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

// ---- defaults -------------------------------------------------------------------------------

#[test]
fn absent_parameters_take_the_defaults_that_with_shapes_and_the_readme_use() {
    use photonmap::scene::defaults::*;
    use photonmap::scene::{RenderParams, Scene};
    let s = load(GOOD).unwrap();
    let w = Scene::with_shapes(s.shapes.clone(), s.materials.clone(), s.lights.clone());
    assert_eq!(s.render, RenderParams::default());
    assert_eq!((&s.render, &s.photon_map), (&w.render, &w.photon_map));
    assert_eq!(s.camera.up, DEFAULT_UP);
    let p = &s.photon_map;
    assert_eq!(
        (p.photons_stored, p.grid_resolution, p.k, p.max_bounces),
        (
            DEFAULT_PHOTONS_STORED,
            DEFAULT_GRID_RESOLUTION,
            DEFAULT_K,
            DEFAULT_MAX_BOUNCES
        )
    );
    // A tenth of the size of the shapes' bounds (the unit sphere: 2).
    assert_eq!(p.max_radius, DEFAULT_MAX_RADIUS_OF_SIZE * 2.0);
    assert_eq!(
        p.projection_resolution,
        photonmap::photon::projection::DEFAULT_RESOLUTION
    );

    // The README's scene format quotes the same numbers.
    let readme = std::fs::read_to_string(common::root().join("README.md")).unwrap();
    let format = readme
        .split("## Scene format")
        .nth(1)
        .and_then(|s| s.split("\n## ").next())
        .expect("README has a scene-format section");
    let line = |key: &str| {
        format
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{key} ")))
            .unwrap_or_else(|| panic!("README's scene format has no {key}"))
    };
    let tenth = if DEFAULT_MAX_RADIUS_OF_SIZE == 0.1 {
        "default a tenth of the scene's size".to_string()
    } else {
        format!("{DEFAULT_MAX_RADIUS_OF_SIZE}")
    };
    for (key, says) in [
        ("up", if DEFAULT_UP == glam::Vec3::Y { "default y".to_string() } else { format!("{DEFAULT_UP}") }),
        ("vfov", format!("({}, {})", VFOV_RANGE.0, VFOV_RANGE.1)),
        ("width", format!("1..={MAX_IMAGE_SIDE}")),
        ("shadow_rays", format!("1..={MAX_SHADOW_RAYS}, default {DEFAULT_SHADOW_RAYS}")),
        ("max_specular_depth", format!("0..={MAX_SPECULAR_DEPTH}, default {DEFAULT_MAX_SPECULAR_DEPTH}")),
        ("photons_stored", format!("1..=2^{}, default {DEFAULT_PHOTONS_STORED}", MAX_PHOTONS_STORED.trailing_zeros())),
        ("grid_resolution", format!("1..={MAX_GRID_SIDE} each, default {DEFAULT_GRID_RESOLUTION:?}")),
        ("k", format!("1..={MAX_K}, default {DEFAULT_K}")),
        ("max_radius", tenth),
        ("max_bounces", format!("1..={MAX_BOUNCES}, default {DEFAULT_MAX_BOUNCES}")),
        ("projection_resolution", format!("{MIN_PROJECTION_RESOLUTION}..={MAX_PROJECTION_RESOLUTION}, default {DEFAULT_PROJECTION_RESOLUTION}")),
        ("glass", format!("ior in [{}, {}]", IOR_RANGE.0, IOR_RANGE.1)),
    ] {
        assert!(line(key).contains(&says), "README: {:?} should say {says:?}", line(key));
    }
}

#[test]
fn arrays_longer_than_their_field_are_refused() {
    // Outside a tagged table too, where toml alone would drop the extra element.
    expect(
        "position = [0.0, 1.0, 3.0]",
        "position = [0.0, 1.0, 3.0, 4.0]",
        3,
        "position",
        "invalid length 4",
    );
    expect(
        "center = [0.0, 0.0, 0.0]",
        "center = [0.0, 0.0, 0.0, 0.0]",
        14,
        "center",
        "invalid length 4",
    );
}
