//! pbrt-v4 and Mitsuba 3 scenes on the command line: `render` and
//! `convert-scene` take them by extension, bad files get one line naming
//! the file and line and write nothing, `--lenient` maps with a note each,
//! and `--set` overrides the converted scene.

use std::path::PathBuf;

use crate::common::{root, Run, TempDir};

fn fixture(name: &str) -> PathBuf {
    root().join("scenes/tests/import").join(name)
}

const HEAD: &str = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nFilm \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\nWorldBegin\nLightSource \"point\" \"rgb I\" [1 1 1]\n";

#[test]
fn convert_scene_writes_the_toml_that_renders() {
    let d = TempDir::new("convert-scene");
    let out = d.join("cornell.toml");
    Run::new(["convert-scene"])
        .arg(fixture("cornell_box.pbrt"))
        .arg(&out)
        .succeeds();
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("[photon_map]") && text.contains("white = "),
        "{text}"
    );
    Run::new([
        "render", "--quiet", "--width", "16", "--height", "16", "--spp", "1",
    ])
    .arg(&out)
    .output_to(d.join("c.png"))
    .succeeds();
    assert!(d.join("c.png").exists());
}

#[test]
fn render_takes_a_pbrt_scene_with_the_toml_flags() {
    let d = TempDir::new("render-pbrt");
    Run::new([
        "render",
        "--quiet",
        "--width",
        "24",
        "--height",
        "16",
        "--set",
        "photon_map.k=20",
    ])
    .arg(fixture("transforms.pbrt"))
    .output_to(d.join("t.png"))
    .succeeds();
    assert_eq!(image::open(d.join("t.png")).unwrap().width(), 24);
    // an override is checked as in a TOML scene, and named so
    Run::new(["render", "--quiet", "--set", "photon_map.k=0"])
        .arg(fixture("transforms.pbrt"))
        .output_to(d.join("u.png"))
        .refused_with("--set photon_map.k:1: photon_map.k: 0 is outside");
}

#[test]
fn bad_scene_files_get_one_line_and_no_output() {
    let d = TempDir::new("bad-pbrt");
    let cases = [
        (
            "unknown.pbrt",
            format!("{HEAD}Shape \"sphere\"\nFrobnicate\n"),
            "unknown.pbrt:7: ",
        ),
        (
            "type.pbrt",
            format!("{HEAD}Shape \"sphere\" \"string radius\" \"1\"\n"),
            "type.pbrt:6: ",
        ),
        (
            "noply.pbrt",
            format!("{HEAD}Shape \"plymesh\" \"string filename\" \"gone.ply\"\n"),
            "noply.pbrt:6: ",
        ),
        (
            "texture.pbrt",
            format!("{HEAD}Texture \"t\" \"spectrum\" \"checkerboard\"\nShape \"sphere\"\n"),
            "texture.pbrt:6: ",
        ),
    ];
    for (name, text, says) in cases {
        let scene = d.join(name);
        std::fs::write(&scene, text).unwrap();
        let stderr = Run::new(["render", "--quiet"])
            .arg(&scene)
            .output_to(d.join("x.png"))
            .refused_with(says);
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        Run::new(["convert-scene"])
            .arg(&scene)
            .arg(d.join("x.toml"))
            .refused_with(says);
        assert!(!d.join("x.toml").exists(), "{name}");
    }
}

#[test]
fn lenient_maps_what_cannot_be_rendered_with_a_note_each() {
    let d = TempDir::new("lenient");
    let scene = d.join("t.pbrt");
    let body = "Texture \"t\" \"spectrum\" \"checkerboard\"\nMaterial \"coateddiffuse\"\nShape \"sphere\"\n";
    std::fs::write(&scene, format!("{HEAD}{body}")).unwrap();
    let stderr = Run::new(["render", "--quiet", "--lenient"])
        .arg(&scene)
        .output_to(d.join("t.png"))
        .stderr();
    let notes: Vec<&str> = stderr.lines().filter(|l| l.starts_with("note: ")).collect();
    assert_eq!(notes.len(), 2, "{stderr}");
    assert!(
        notes[0].contains("t.pbrt:6: Texture") && notes[1].contains("t.pbrt:7:"),
        "{stderr}"
    );
}

#[test]
fn mitsuba_scenes_take_d_parameters_and_name_xml_errors_by_line() {
    let d = TempDir::new("mitsuba");
    let out = d.join("c.toml");
    Run::new(["convert-scene", "-D", "res=32"])
        .arg(fixture("cornell_box.xml"))
        .arg(&out)
        .succeeds();
    assert!(std::fs::read_to_string(&out)
        .unwrap()
        .contains("width = 32"));
    // on render, -D sets the XML's parameter, and a TOML path overrides the TOML
    Run::new([
        "render",
        "--quiet",
        "-D",
        "res=16",
        "-D",
        "photon_map.photons_stored=2000",
    ])
    .arg(fixture("cornell_box.xml"))
    .output_to(d.join("c.png"))
    .succeeds();
    assert_eq!(image::open(d.join("c.png")).unwrap().width(), 16);
    let bad = d.join("bad.xml");
    std::fs::write(&bad, "<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"1\">\n  </shape>\n</scene>\n").unwrap();
    let stderr = Run::new(["render", "--quiet"])
        .arg(&bad)
        .output_to(d.join("b.png"))
        .refused_with("bad.xml:4: ");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}
