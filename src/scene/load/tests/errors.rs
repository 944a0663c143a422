//! Each kind of malformed scene gives its own error, naming file, line and
//! field: one change at a time to the good scene (scenes/tests/one_sphere.toml).

use std::path::{Path, PathBuf};

use super::{dir_with, good};
use crate::scene::{load_scene, load_scene_str, Scene, SceneError};

pub(super) fn load(text: &str) -> Result<Scene, SceneError> {
    load_scene_str(text, Path::new("scenes/broken.toml"))
}

/// Replaces `from` in the good scene and expects an error at `line` on `field`
/// whose message contains `says`.
fn expect(from: &str, to: &str, line: usize, field: &str, says: &str) {
    assert!(good().contains(from), "{from:?} not in the good scene");
    let text = good().replacen(from, to, 1);
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

/// Loads `text` and expects an error at `line` on `field`; returns it for
/// the caller's checks of its message.
fn error_at(text: &str, line: usize, field: &str) -> SceneError {
    let e = load(text).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (line, field), "{e}");
    e
}

/// The good scene with its point light's fields replaced by `fields`.
fn with_light(fields: &str) -> String {
    good().replace(
        "type = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]",
        fields,
    )
}

/// The good scene with its sphere's fields but the material replaced by `fields`.
fn with_shape(fields: &str) -> String {
    good().replace(
        "type = \"sphere\"\ncenter = [0.0, 0.0, 0.0]\nradius = 1.0",
        fields,
    )
}

#[test]
fn the_good_scene_loads() {
    let s = load(good()).unwrap();
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
    let text = good().split("[[light]]").next().unwrap();
    let e = load(text).unwrap_err();
    assert_eq!(e.field, "light");
    assert!(e.message.contains("no [[light]]"), "{e}");
}

#[test]
fn area_light_normal_off_its_plane() {
    let text = with_light(
        "type = \"area\"\ncorner = [0.0, 3.0, 0.0]\nedge1 = [1.0, 0.0, 0.0]\nedge2 = [0.0, 0.0, 1.0]\nnormal = [1.0, 0.0, 0.0]\nradiance = [1.0, 1.0, 1.0]",
    );
    error_at(&text, 23, "light[0].normal");
}

#[test]
fn zero_area_light() {
    let text = with_light(
        "type = \"area\"\ncorner = [0.0, 3.0, 0.0]\nedge1 = [1.0, 0.0, 0.0]\nedge2 = [2.0, 0.0, 0.0]\nradiance = [1.0, 1.0, 1.0]",
    );
    let e = error_at(&text, 22, "light[0].edge2");
    assert!(e.message.contains("no area"), "{e}");
}

#[test]
fn non_planar_polygon() {
    let text = with_shape(
        "type = \"polygon\"\nvertices = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.5]]",
    );
    let e = error_at(&text, 14, "shape[0].vertices");
    assert!(e.message.contains("planar"), "{e}");
}

fn with_mesh(dir: &Path, obj_name: &str) -> PathBuf {
    let text = with_shape(&format!("type = \"mesh\"\nfile = \"{obj_name}\""));
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn missing_obj_names_the_path() {
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    let e = load_scene(&with_mesh(dir, "nowhere.obj")).unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (14, "shape[0].file"), "{e}");
    assert!(
        e.message
            .contains(&dir.join("nowhere.obj").display().to_string()),
        "{e}"
    );
}

#[test]
fn obj_with_nan_vertex_is_refused() {
    let temp = dir_with("bad.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n");
    let dir = temp.path();
    let e = load_scene(&with_mesh(dir, "bad.obj")).unwrap_err();
    assert!(e.message.contains("finite"), "{e}");
}

#[test]
fn good_obj_loads_as_triangles() {
    let temp = dir_with(
        "quad.obj",
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    );
    let dir = temp.path();
    let s = load_scene(&with_mesh(dir, "quad.obj")).unwrap();
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

/// The good scene's material made a conductor with `fields`.
fn metal(fields: &str) -> String {
    good().replacen(
        "{ type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }",
        &format!("{{ type = \"conductor\", {fields} }}"),
        1,
    )
}

#[test]
fn conductors_load_by_name_or_index() {
    use crate::scene::Material;
    let gold = load(&metal("metal = \"Au\", alpha = 0.2")).unwrap();
    let Material::Conductor {
        eta,
        k,
        tint,
        alpha,
        ..
    } = gold.materials[0]
    else {
        panic!("{:?}", gold.materials[0]);
    };
    assert_eq!(
        (eta.x, k.x, tint, alpha),
        (0.143, 3.983, glam::Vec3::ONE, 0.2)
    );
    let own = load(&metal(
        "eta = [1.5, 1.0, 0.5], k = [3.0, 2.0, 1.0], tint = [0.5, 0.5, 0.5]",
    ))
    .unwrap();
    assert!(matches!(own.materials[0], Material::Conductor { alpha, .. } if alpha == 0.0));
    // Below 1e-3 a metal is smooth, as pbrt-v4 treats it.
    let nearly = load(&metal("metal = \"Ag\", alpha = 0.0005")).unwrap();
    assert!(!nearly.materials[0].is_glossy());
    // pbrt's microfacet model by default; Mitsuba's when asked.
    let model = |fields: &str| match load(&metal(fields)).unwrap().materials[0] {
        Material::Conductor { microfacet, .. } => microfacet,
        m => panic!("{m:?}"),
    };
    assert_eq!(model("metal = \"Au\"").bits(), 0);
    let mitsuba =
        model("metal = \"Au\", alpha = 0.3, distribution = \"beckmann\", masking = \"separable\"");
    assert_eq!(mitsuba, crate::scene::Microfacet::mitsuba(true));
}

#[test]
fn bad_conductors_name_their_field() {
    let e = error_at(
        &metal("metal = \"Unobtainium\""),
        10,
        "materials.white.metal",
    );
    assert!(
        e.message.contains("unknown metal") && e.message.contains("Au"),
        "{e}"
    );
    let e = error_at(
        &metal("metal = \"Au\", alpha = 1.5"),
        10,
        "materials.white.alpha",
    );
    assert!(e.message.contains("[0, 1]"), "{e}");
    let e = error_at(
        &metal("eta = [0.0, 1.0, 1.0], k = [1.0, 1.0, 1.0]"),
        10,
        "materials.white.eta",
    );
    assert!(e.message.contains("(0, 100]"), "{e}");
    let e = error_at(
        &metal("eta = [1.0, 1.0, 1.0], k = [1.0, -1.0, 1.0]"),
        10,
        "materials.white.k",
    );
    assert!(e.message.contains("[0, 100]"), "{e}");
    let e = error_at(&metal("eta = [1.0, 1.0, 1.0]"), 10, "materials.white.eta");
    assert!(e.message.contains("`eta` and `k` together"), "{e}");
    let e = error_at(
        &metal("metal = \"Au\", k = [1.0, 1.0, 1.0]"),
        10,
        "materials.white.metal",
    );
    assert!(e.message.contains("not both"), "{e}");
    let e = error_at(
        &metal("metal = \"Au\", tint = [1.0, 2.0, 1.0]"),
        10,
        "materials.white.tint",
    );
    assert!(e.message.contains("[0, 1]"), "{e}");
    let e = error_at(
        &metal("metal = \"Au\", distribution = \"phong\""),
        10,
        "materials.white.distribution",
    );
    assert!(e.message.contains("`ggx` or `beckmann`"), "{e}");
    let e = error_at(
        &metal("metal = \"Au\", masking = \"none\""),
        10,
        "materials.white.masking",
    );
    assert!(
        e.message.contains("`height-correlated` or `separable`"),
        "{e}"
    );
}
