//! Bad files get one error naming the file and line, and what photonmap
//! cannot render is refused there, or mapped under --lenient with a note.

use super::*;

const HEAD: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\n";

/// The error converting `body` after a valid head (4 lines).
fn pbrt_error(body: &str) -> SceneError {
    let text = format!("{HEAD}{body}");
    convert_default("bad.pbrt", &text).unwrap_err()
}

fn assert_at(e: &SceneError, file: &str, line: usize, words: &str) {
    assert!(e.file.ends_with(file), "{e}");
    assert_eq!(e.line, line, "{e}");
    let text = e.to_string();
    assert!(text.contains(words), "{text}");
    assert_eq!(text.lines().count(), 1, "{text}");
}

#[test]
fn pbrt_syntax_and_parameter_errors_name_their_line() {
    assert_at(
        &pbrt_error("Shape \"sphere\"\nFrobnicate 1 2\n"),
        "bad.pbrt",
        6,
        "unknown directive `Frobnicate`",
    );
    assert_at(
        &pbrt_error("Shape \"sphere\"\n  \"string radius\" \"1\"\n"),
        "bad.pbrt",
        6,
        "is declared \"string\"",
    );
    assert_at(
        &pbrt_error("Shape \"sphere\" \"float radius\" [ \"a\" ]\n"),
        "bad.pbrt",
        5,
        "takes numbers",
    );
    assert_at(
        &pbrt_error("Shape \"sphere\" \"float radus\" 2\n"),
        "bad.pbrt",
        5,
        "unknown parameter \"float radus\"",
    );
    assert_at(
        &pbrt_error(
            "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 7]\n",
        ),
        "bad.pbrt",
        5,
        "names vertex 7",
    );
    assert_at(
        &pbrt_error("AttributeEnd\n"),
        "bad.pbrt",
        5,
        "without AttributeBegin",
    );
    assert_at(
        &pbrt_error("Shape \"sphere\" \"float radius\" [ 1 2\n"),
        "bad.pbrt",
        5,
        "not closed",
    );
    assert_at(
        &pbrt_error("Include \"no_such_file.pbrt\"\n"),
        "bad.pbrt",
        5,
        "cannot read",
    );
}

#[test]
fn a_missing_or_truncated_ply_names_its_file_and_line() {
    let e = pbrt_error("Shape \"plymesh\"\n  \"string filename\" \"no_such.ply\"\n");
    assert_at(&e, "bad.pbrt", 6, "cannot read");
    let full = std::fs::read(dir().join("tall_block_le.ply")).unwrap();
    let cut = dir().join("cut.ply");
    let files = Patched(HashMap::from([(
        cut.clone(),
        full[..full.len() - 7].to_vec(),
    )]));
    let text = format!("{HEAD}Shape \"plymesh\" \"string filename\" \"cut.ply\"\n");
    let e = convert_with("bad.pbrt", &text, &files, &ImportOptions::default()).unwrap_err();
    assert_at(&e, "cut.ply", 10, "binary data after end_header");
}

#[test]
fn what_photonmap_cannot_render_is_refused_or_mapped_with_a_note() {
    let cases = [
        ("Material \"coateddiffuse\" \"rgb reflectance\" [0.2 0.3 0.4]\nShape \"sphere\"\n", "Material \"coateddiffuse\""),
        ("Material \"conductor\" \"float uroughness\" 0.2 \"float vroughness\" 0.1\nShape \"sphere\"\n", "anisotropic roughness"),
        ("Material \"diffuse\" \"texture reflectance\" \"checks\"\nShape \"sphere\"\n", "\"texture reflectance\""),
        ("LightSource \"infinite\" \"rgb L\" [1 1 1]\nShape \"sphere\"\n", "LightSource \"infinite\""),
        ("MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\nShape \"sphere\"\n", "participating media"),
        ("AttributeBegin\nAreaLightSource \"diffuse\" \"bool twosided\" true\nShape \"bilinearmesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0 1 1 0]\nAttributeEnd\n", "two-sided"),
    ];
    for (body, what) in cases {
        let e = pbrt_error(body);
        assert!(
            e.to_string().contains(what) && e.to_string().contains("--lenient"),
            "{e}"
        );
        assert_eq!(
            e.line,
            5 + body
                .lines()
                .position(|l| !l.starts_with("AttributeBegin"))
                .unwrap(),
            "{e}"
        );
        let text = format!("{HEAD}{body}");
        let lenient = ImportOptions {
            lenient: true,
            ..ImportOptions::default()
        };
        let c = convert_text("bad.pbrt", &text, &lenient).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(c.notes.len(), 1, "{:?}", c.notes);
        assert!(c.notes[0].contains(what), "{:?}", c.notes);
        load_scene_str(&c.toml, Path::new("t")).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn a_scene_without_camera_or_light_is_refused() {
    let e = convert_default("bad.pbrt", "WorldBegin\nLightSource \"point\"\n").unwrap_err();
    assert!(e.to_string().contains("no camera"), "{e}");
    let text = "Camera \"perspective\"\nWorldBegin\nShape \"sphere\"\n";
    let e = convert_default("bad.pbrt", text).unwrap_err();
    assert!(e.to_string().contains("no light"), "{e}");
}

const XML_HEAD: &str = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n<emitter type=\"point\"/>\n";

fn xml_error(body: &str) -> SceneError {
    let text = format!("{XML_HEAD}{body}</scene>\n");
    convert_default("bad.xml", &text).unwrap_err()
}

#[test]
fn mitsuba_errors_name_their_line() {
    assert_at(
        &xml_error("<shape type=\"sphere\">\n<float name=\"radius\" value=\"1\">\n</shape>\n"),
        "bad.xml",
        6,
        "expected 'float' tag, not 'shape'",
    );
    assert_at(
        &xml_error("<shap type=\"sphere\"/>\n"),
        "bad.xml",
        4,
        "unknown element <shap>",
    );
    assert_at(
        &xml_error("<shape type=\"sphere\">\n<string name=\"radius\" value=\"1\"/>\n</shape>\n"),
        "bad.xml",
        5,
        "it must be a <float>",
    );
    assert_at(
        &xml_error("<shape type=\"sphere\">\n<float name=\"radius\" value=\"$r\"/>\n</shape>\n"),
        "bad.xml",
        5,
        "$r has no value",
    );
    assert_at(
        &xml_error("<shape type=\"sphere\">\n<float name=\"radios\" value=\"1\"/>\n</shape>\n"),
        "bad.xml",
        5,
        "unknown property `radios`",
    );
    assert_at(
        &xml_error(
            "<shape type=\"ply\">\n<string name=\"filename\" value=\"gone.ply\"/>\n</shape>\n",
        ),
        "bad.xml",
        4,
        "cannot read",
    );
    assert_at(
        &xml_error("<shape type=\"sphere\"><bsdf type=\"roughplastic\"/></shape>\n"),
        "bad.xml",
        4,
        "--lenient",
    );
    assert_at(
        &xml_error("<emitter type=\"envmap\"/>\n"),
        "bad.xml",
        4,
        "--lenient: left out",
    );
}

/// Metals import as conductors: Mitsuba's `roughconductor` (Beckmann by
/// default) in Mitsuba's own microfacet model, pbrt's rough conductor with
/// its roughness remapped; anisotropy is refused strictly.
#[test]
fn rough_metals_import_in_their_renderers_models() {
    let xml = format!(
        "{XML_HEAD}<shape type=\"sphere\"><bsdf type=\"roughconductor\">\
         <string name=\"material\" value=\"Au\"/><float name=\"alpha\" value=\"0.2\"/></bsdf></shape>\n</scene>\n"
    );
    let toml = convert_default("metal.xml", &xml).unwrap().toml;
    assert!(toml.contains("type = \"conductor\""), "{toml}");
    assert!(
        toml.contains("alpha = 0.2, distribution = \"beckmann\", masking = \"separable\""),
        "{toml}"
    );
    let pbrt = "Camera \"perspective\"\nWorldBegin\nLightSource \"point\"\n\
                Material \"conductor\" \"float roughness\" 0.04\nShape \"sphere\"\n";
    let toml = convert_default("metal.pbrt", pbrt).unwrap().toml;
    assert!(toml.contains("type = \"conductor\""), "{toml}");
    assert!(
        toml.contains("alpha = 0.2 }"),
        "sqrt(0.04) and pbrt's model: {toml}"
    );
    let e = xml_error(
        "<shape type=\"sphere\"><bsdf type=\"roughconductor\"><float name=\"alpha_u\" value=\"0.1\"/>\
         <float name=\"alpha_v\" value=\"0.3\"/></bsdf></shape>\n",
    );
    assert!(e.to_string().contains("anisotropic alpha"), "{e}");
}
