//! `photonmap reference` writes an SPPM reference and its error model, and
//! `bench accuracy` measures run time against error with it (`--only` runs
//! the matching rows, `--regions` scores surfaces and rectangles; without a
//! reference it says how to make one).

use std::path::Path;

use crate::common::{assert_output_modes, Run, TempDir};

#[test]
fn reference_and_accuracy_bench_write_their_results() {
    let d = TempDir::new("accuracy");
    let reference = d.join("gb.sppm.exr");
    Run::new(["reference", "--scale", "8", "--iterations", "8"])
        .args(["--photons-per-iteration", "4096", "--quiet"])
        .writing("--out", &reference)
        .scene("glass_ball")
        .umask(0o077)
        .succeeds();
    // The EXR and its JSON are 0600, as a new file is under umask 077.
    assert!(assert_output_modes(&d, 0o077) >= 2);
    let info: serde_json::Value =
        serde_json::from_slice(&std::fs::read(reference.with_extension("json")).unwrap()).unwrap();
    assert_eq!(
        (
            info["width"].as_u64(),
            info["iterations"].as_u64(),
            info["method"].as_str()
        ),
        (Some(64), Some(8), Some("sppm"))
    );
    assert!(info["residual_noise_rmse"].as_f64().unwrap() > 0.0);
    let bound = info["bias_bound_rmse_95"].as_f64().unwrap();
    assert!(bound > 0.0 && bound >= info["bias_estimate_rmse"].as_f64().unwrap());
    assert!(info["bias_resolved"].is_boolean() && info["bias_model"].is_string());
    assert!(info.get("residual_bias_rmse").is_none());
    assert!(info["command"]
        .as_str()
        .unwrap()
        .starts_with("photonmap reference"));

    let results = d.join("results");
    let v = Run::new([
        "bench", "accuracy", "--quick", "--quiet", "--json", "--scene",
    ])
    .scene("glass_ball")
    .arg("--reference")
    .arg(&reference)
    .writing("--out", &results)
    .umask(0o022)
    .json();
    // Its CSV, JSON, SVG and PNGs are 0644, as new files are under umask 022.
    assert!(assert_output_modes(&results, 0o022) >= 4);
    let runs = v["runs"].as_array().unwrap();
    assert!(runs.len() >= 10, "{} runs", runs.len());
    let num = |r: &serde_json::Value, f: &str| r[f].as_f64().unwrap();
    for r in runs {
        assert!(num(r, "seconds") > 0.0 && num(r, "rmse") > 0.0, "{r}");
        // Bias and noise split one render's error: neither exceeds it by much.
        assert!(
            num(r, "bias_rmse") >= 0.0 && num(r, "noise_rmse") > 0.0,
            "{r}"
        );
    }
    assert!(runs.iter().any(|r| r["method"] == "sppm"));
    assert!(runs.iter().any(|r| r["method"] == "paper"));
    let front: Vec<&serde_json::Value> = runs
        .iter()
        .filter(|r| r["on_pareto_front"] == true)
        .collect();
    assert!(!front.is_empty());
    // No run on the front is beaten on both time and error by another.
    for f in &front {
        let (t, e) = (num(f, "seconds"), num(f, "rmse"));
        assert!(!runs
            .iter()
            .any(|r| num(r, "seconds") < t && num(r, "rmse") < e));
    }
    assert!(runs.iter().any(|r| r["label"] == v["recommended"]));
    for f in [
        "accuracy.csv",
        "accuracy.json",
        "accuracy.svg",
        "accuracy.png",
        "bias.png",
    ] {
        assert!(results.join(f).is_file(), "{f}");
    }
    assert!(v["bias_map_scale"].as_f64().unwrap() > 0.0);
    assert!(std::fs::read_to_string(results.join("accuracy.svg"))
        .unwrap()
        .contains("<polyline"));
    accuracy_only_runs_the_matching_rows(&reference, &d.join("only"));
    accuracy_scores_regions(&reference, &d);
    // Without a reference it says how to make one.
    Run::new(["bench", "accuracy", "--scene"])
        .scene("ring")
        .arg("--reference")
        .arg(d.join("none.exr"))
        .refused_with("photonmap reference");
}

/// `bench accuracy --only` runs the matching rows; matching none is an error
/// that lists them.
fn accuracy_only_runs_the_matching_rows(reference: &Path, out: &Path) {
    let only = |texts: &[&str]| {
        Run::new([
            "bench", "accuracy", "--quiet", "--json", "--seeds", "2", "--scene",
        ])
        .scene("glass_ball")
        .arg("--reference")
        .arg(reference)
        .writing("--out", out)
        .args(texts.iter().flat_map(|t| ["--only", t]))
    };
    let v = only(&["k x2", "k x0.5"]).json();
    assert_eq!(v["runs"].as_array().unwrap().len(), 2, "{v}");
    assert!(
        v["bias_map_scale"].is_null(),
        "no defaults run, no bias map"
    );
    only(&["no such run"]).refused_with("scene defaults, photons x");
}

/// `bench accuracy --regions --mask`: the regions are the surfaces seen first
/// and the named rectangles, each cut to the mask; a rectangle over every
/// compared pixel scores the run's own energy.
fn accuracy_scores_regions(reference: &Path, d: &Path) {
    let mask = d.join("left.png");
    image::GrayImage::from_fn(64, 48, |x, _| image::Luma([if x < 48 { 255 } else { 0 }]))
        .save(&mask)
        .unwrap();
    let out = d.join("regions");
    let bench = |regions: &[&str]| {
        Run::new([
            "bench", "accuracy", "--quiet", "--json", "--seeds", "2", "--only",
        ])
        .arg("=scene defaults")
        .args(["--scene", "glass_ball", "--mask"])
        .arg(&mask)
        .arg("--reference")
        .arg(reference)
        .writing("--out", &out)
        .args(regions.iter().flat_map(|r| ["--region", r]))
    };
    let v = bench(&["whole=0:64:0:48", "right=48:64:0:48"]).json();
    assert_eq!(v["pixels_compared"], 48 * 48, "{v}");
    let sizes = v["regions"].as_array().unwrap();
    let names: Vec<&str> = sizes.iter().map(|r| r["name"].as_str().unwrap()).collect();
    assert!(!names.contains(&"right"), "outside the mask: {names:?}");
    let whole = names.iter().position(|&n| n == "whole").unwrap();
    assert_eq!(sizes[whole]["pixels"], 48 * 48);
    let surfaces: u64 = sizes[..whole]
        .iter()
        .map(|r| r["pixels"].as_u64().unwrap())
        .sum();
    assert!(whole > 0 && surfaces <= 48 * 48, "{sizes:?}");
    let runs = v["runs"].as_array().unwrap();
    assert_eq!(runs.len(), 1, "{v}");
    let scores = runs[0]["regions"].as_array().unwrap();
    assert_eq!(scores.len(), sizes.len());
    let energy = runs[0]["energy"].as_f64().unwrap();
    let whole_energy = scores[whole]["energy"].as_f64().unwrap();
    assert!(
        (whole_energy - energy).abs() < 1e-9 * energy,
        "{whole_energy} vs {energy}"
    );
    for s in scores {
        assert!(s["energy"].as_f64().unwrap() > 0.0 && s["rel_rmse"].as_f64().unwrap() > 0.0);
        assert!(s["energy_noise"].as_f64().unwrap() >= 0.0, "{s}");
    }
    for f in ["regions.csv", "regions.md", "bias/scene-defaults.png"] {
        assert!(out.join(f).is_file(), "{f}");
    }
    bench(&["past=0:65:0:10"]).refused_with("outside the reference's 64 x 48");
    bench(&["no bounds"]).refused_with("NAME=X0:X1:Y0:Y1");
}
