//! `photonmap info` and `photonmap scenes`, and the installed binary away
//! from its source tree: the paper scenes by name, the embedded scenes
//! listed, the quick stress suite run in full.

use crate::common::{Printed, Run, TempDir};

#[test]
fn info_names_the_renderer_and_limits() {
    let v = Run::new(["info", "--json"]).json();
    assert!(v["gl_renderer"].as_str().is_some_and(|s| !s.is_empty()));
    assert!(v["max_texture_size"].as_i64().unwrap() >= 4096);
    assert_eq!(v["stencil_bits"], 8);
}

/// The installed binary, away from its source tree: a paper scene renders by
/// name, `scenes` lists the embedded scenes, and the quick stress suite runs
/// every one of its cases (none may be skipped or fail to run).
#[test]
fn the_binary_alone_renders_by_name_lists_scenes_and_runs_the_stress_suite() {
    let d = TempDir::new("alone");
    let bin = d.join("photonmap");
    std::fs::copy(env!("CARGO_BIN_EXE_photonmap"), &bin).unwrap();
    let run = |args: &[&str]| Run::of(&bin, args).in_dir(&d).succeeds();
    run(&[
        "render", "ring", "-o", "ring.png", "--quiet", "--width", "64", "--height", "48",
    ]);
    assert_eq!(image::open(d.join("ring.png")).unwrap().width(), 64);
    let listed = run(&["scenes"]).stdout_text();
    for name in [
        "glass_ball",
        "ring",
        "cornell_box",
        "variants/furnace_64_bounces",
    ] {
        assert!(listed.contains(name), "{listed}");
    }
    let out = run(&["bench", "stress", "--quick", "--json", "--quiet"]);
    let mut cases: Vec<serde_json::Value> = out
        .stdout_text()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // The last line sums the cases up.
    let summary = cases.pop().unwrap();
    assert_eq!(summary["summary"]["cases"], cases.len(), "{summary}");
    assert_eq!(summary["summary"]["fail"], 0, "{summary}");
    assert!(cases.len() >= 15, "{} cases", cases.len());
    for c in &cases {
        assert_ne!(c["outcome"], "fail", "{c}");
        assert!(
            !c["message"].as_str().unwrap().contains("could not run"),
            "{c}"
        );
    }
    // A name that is neither a file nor an embedded scene is refused clearly.
    Run::of(&bin, ["render", "no_such_scene", "-o", "x.png"])
        .in_dir(&d)
        .refused_with("no_such_scene");
}
