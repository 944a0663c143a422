//! The CI reports of `compare` and `regress`: the JUnit XML read back by an
//! independent XML parser, and the HTML page opened in headless Chromium,
//! every picture of which must load.

use std::path::{Path, PathBuf};

use crate::common::{self, browser, Printed, Run, TempDir};

/// (test case name, its failure message if any) of a JUnit file.
fn junit_cases(path: &Path) -> Vec<(String, Option<String>)> {
    let text = std::fs::read_to_string(path).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{e}: {text}"));
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "testsuites", "{text}");
    root.descendants()
        .filter(|n| n.has_tag_name("testcase"))
        .map(|n| {
            let failure = n
                .children()
                .find(|c| c.has_tag_name("failure"))
                .map(|f| f.attribute("message").unwrap_or_default().to_string());
            (n.attribute("name").unwrap().to_string(), failure)
        })
        .collect()
}

fn render_exr(d: &Path, seed: &str) -> PathBuf {
    let exr = d.join(format!("seed{seed}.exr"));
    Run::new(["render", "glass_ball", "--quiet", "--direct-only"])
        .args(["--width", "40", "--height", "30", "--seed", seed])
        .output_to(&exr)
        .succeeds();
    exr
}

/// compare's JUnit has one test case, failed when a --fail-* threshold
/// failed; its HTML page shows three pictures, all of which load (and a page
/// whose picture is broken is caught); bad report paths write nothing.
#[test]
fn compare_writes_a_junit_case_and_an_html_page_whose_images_load() {
    let d = TempDir::new("compare-reports");
    let (a, b) = (render_exr(&d, "1"), render_exr(&d, "2"));
    let (xml, html) = (d.join("r.xml"), d.join("r.html"));
    let out = Run::new(["compare", "--fail-rmse", "1e-6"])
        .arg(&a)
        .arg(&b)
        .writing("--junit", &xml)
        .writing("--html", &html)
        .arg("--diff")
        .arg(d.join("diff.png"))
        .run();
    assert_eq!(out.status.code(), Some(1), "{}", out.stderr_text());
    let cases = junit_cases(&xml);
    assert_eq!(cases.len(), 1, "{cases:?}");
    let failure = cases[0].1.as_deref().expect("a failure element");
    assert!(failure.contains("rmse"), "{failure}");
    assert_eq!(browser::images_loaded(&html), (3, 3));
    // The check sees a picture that does not decode.
    let page = std::fs::read_to_string(&html).unwrap();
    let at = page.find("base64,").unwrap() + "base64,".len();
    let broken = d.join("broken.html");
    std::fs::write(&broken, format!("{}AAAA{}", &page[..at], &page[at + 200..])).unwrap();
    assert_eq!(browser::images_loaded(&broken), (2, 3));
    // An identical pair passes: no failure element.
    Run::new(["compare", "--fail-rmse", "1e-6"])
        .arg(&a)
        .arg(&a)
        .writing("--junit", &xml)
        .succeeds();
    assert_eq!(junit_cases(&xml)[0].1, None);
    // Bad report paths are refused before anything is written.
    let (x2, h2) = (d.join("new.xml"), d.join("missing").join("r.html"));
    Run::new(["compare"])
        .arg(&a)
        .arg(&b)
        .writing("--junit", &x2)
        .writing("--html", &h2)
        .refused_with("does not exist");
    Run::new(["compare"])
        .arg(&a)
        .arg(&b)
        .writing("--junit", d.join("r.txt"))
        .refused_with("must end in .xml");
}

/// regress writes one JUnit file and one HTML page for all its scenes: RING
/// passes, a copy with a 10% brighter light (tested against RING's
/// reference) fails, and the page's eight pictures load.
#[test]
fn regress_writes_one_report_for_many_scenes() {
    let d = TempDir::new("regress-reports");
    let refs = d.join("ref");
    std::fs::create_dir_all(&refs).unwrap();
    for ext in ["exr", "var.exr", "json"] {
        let from = common::root().join(format!("reference_images/ring.{ext}"));
        for name in ["ring", "ring_bright"] {
            std::fs::copy(&from, refs.join(format!("{name}.{ext}"))).unwrap();
        }
    }
    let text = std::fs::read_to_string(common::scene_file("ring")).unwrap();
    let bright = d.join("ring_bright.toml");
    let edited = common::replace_once(
        &text,
        "intensity = [40.0, 40.0, 40.0]",
        "intensity = [44.0, 44.0, 44.0]",
    );
    std::fs::write(&bright, edited).unwrap();
    let (xml, html) = (d.join("r.xml"), d.join("r.html"));
    let run = |scenes: &[&Path]| {
        Run::new(["regress", "--json", "--reference"])
            .arg(&refs)
            .args(scenes)
            .writing("--junit", &xml)
            .writing("--html", &html)
            .writing("--out", d.join("out"))
    };
    let missing = d.join("nope.toml");
    run(&[&common::scene_file("ring"), &missing]).refused_with("nope.toml");
    let out = run(&[&common::scene_file("ring"), &bright]).run();
    assert_eq!(out.status.code(), Some(1), "{}", out.stderr_text());
    let v = out.json();
    let passed: Vec<bool> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["passed"].as_bool().unwrap())
        .collect();
    assert_eq!(passed, [true, false], "{v}");
    let cases = junit_cases(&xml);
    let names: Vec<&str> = cases.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(names, ["ring", "ring_bright"]);
    assert!(cases[0].1.is_none() && cases[1].1.is_some(), "{cases:?}");
    assert!(d.join("out/ring_bright/actual.exr").is_file());
    assert!(
        !d.join("out/ring").exists(),
        "a passing scene writes no images"
    );
    assert_eq!(browser::images_loaded(&html), (8, 8));
    Run::new(["regress", "--name", "x", "--reference"])
        .arg(&refs)
        .arg(common::scene_file("ring"))
        .arg(&bright)
        .refused_with("--name");
    Run::new(["regress", "--update", "--reference"])
        .arg(&refs)
        .arg(common::scene_file("ring"))
        .writing("--junit", d.join("update.xml"))
        .refused_with("--update");
}
