//! The `photonmap` command as a user runs it.

use crate::common;

use std::path::{Path, PathBuf};
use std::process::Command;

use photonmap::render::Image;

fn photonmap() -> Command {
    Command::new(env!("CARGO_BIN_EXE_photonmap"))
}

/// The command succeeded; if not, its stderr says why.
fn assert_ok(out: &std::process::Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A command that failed with one line of error naming `says`.
fn assert_refused(out: &std::process::Output, says: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "accepted; stderr: {stderr}");
    assert!(stderr.contains(says), "no '{says}' in: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("photonmap-cli-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scene(name: &str) -> PathBuf {
    common::root().join("scenes").join(format!("{name}.toml"))
}

#[test]
fn render_writes_png_and_exr_the_same_way_up() {
    let d = tmp("render");
    let (png, exr) = (d.join("c.png"), d.join("c.exr"));
    let out = photonmap()
        .args(["render", "--quiet", "--width", "48", "--height", "40"])
        .arg(scene("cornell_box"))
        .arg("-o")
        .arg(&png)
        .arg("--exr")
        .arg(&exr)
        .output()
        .unwrap();
    assert_ok(&out);
    let linear = Image::read_exr(&exr).unwrap();
    assert_eq!((linear.width, linear.height), (48, 40));
    let srgb = image::open(&png).unwrap().to_rgb8();
    assert_eq!(srgb.dimensions(), (48, 40));
    // The ceiling light is at the top: the brightest row is in the top quarter, in both files.
    let brightest_exr = (0..40).max_by(|&a, &b| {
        let row = |y| (0..48).map(|x| linear.get(x, y)[0]).sum::<f32>();
        row(a).total_cmp(&row(b))
    });
    assert!(
        brightest_exr.unwrap() < 10,
        "brightest EXR row {brightest_exr:?}"
    );
    for (x, y, p) in srgb.enumerate_pixels() {
        let v = linear.get(x, y);
        let expect = (photonmap::image::linear_to_srgb(v[0]) * 255.0 + 0.5) as u8;
        assert_eq!(p[0], expect, "pixel ({x}, {y})");
    }
}

#[test]
fn the_same_seed_gives_the_same_image_and_another_seed_another() {
    let d = tmp("seed");
    let run = |seed: &str, name: &str| {
        let exr = d.join(name);
        let st = photonmap()
            .args([
                "render", "--quiet", "--width", "40", "--height", "30", "--seed", seed,
            ])
            .arg(scene("glass_ball"))
            .arg("-o")
            .arg(d.join("x.png"))
            .arg("--exr")
            .arg(&exr)
            .status()
            .unwrap();
        assert!(st.success());
        Image::read_exr(&exr).unwrap()
    };
    let (a, b, c) = (run("7", "a.exr"), run("7", "b.exr"), run("8", "c.exr"));
    assert_eq!(a, b, "same seed, same driver: identical images");
    assert_ne!(a, c, "another seed: other shadow samples");
}

#[test]
fn a_malformed_scene_fails_cleanly_and_writes_nothing() {
    let d = tmp("bad");
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        std::fs::read_to_string(scene("ring"))
            .unwrap()
            .replace("radius = 1.0", "radius = -1.0"),
    )
    .unwrap();
    let png = d.join("out.png");
    let out = photonmap()
        .args(["render", "--quiet"])
        .arg(&bad)
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&format!("{}:", bad.display())) && err.contains("shape[1].radius"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(
        std::fs::read_dir(&d).unwrap().count(),
        1,
        "only the scene file is there"
    );
}

#[test]
fn impossible_parameters_say_the_allowed_range() {
    let d = tmp("range");
    let out = photonmap()
        .args(["render", "--quiet", "--width", "0"])
        .arg(scene("ring"))
        .arg("-o")
        .arg(d.join("x.png"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("1..=16384"));
    let out = photonmap()
        .args(["render", "--quiet"])
        .arg(scene("ring"))
        .arg("-o")
        .arg(d.join("missing/x.png"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("does not exist"));
    let out = photonmap()
        .args(["render", "--quiet"])
        .arg(scene("ring"))
        .arg("-o")
        .arg(d.join("x.jpg"))
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&out.stderr).contains(".png"));
    assert_eq!(std::fs::read_dir(&d).unwrap().count(), 0, "nothing written");
}

#[test]
fn info_names_the_renderer_and_limits() {
    let out = photonmap().args(["info", "--json"]).output().unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["gl_renderer"].as_str().is_some_and(|s| !s.is_empty()));
    assert!(v["max_texture_size"].as_i64().unwrap() >= 4096);
    assert_eq!(v["stencil_bits"], 8);
}

/// `photonmap photons --json` on a paper scene, which must succeed.
fn photons_json(name: &str, extra: &[&str]) -> serde_json::Value {
    let out = photonmap()
        .args(["photons", "--json"])
        .args(extra)
        .arg(scene(name))
        .output()
        .unwrap();
    assert_ok(&out);
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn photons_reports_the_stored_count_for_both_builds() {
    for build in ["bitonic", "stencil"] {
        let v = photons_json("glass_ball", &["--build", build]);
        assert_eq!(v["trace"]["target"], 5000);
        let stored = v["trace"]["stored"].as_u64().unwrap();
        assert!((5000..=5008).contains(&stored), "{v}");
        let (in_map, in_grid) = (
            v["photons_in_map"].as_u64().unwrap(),
            v["photons_in_grid"].as_u64().unwrap(),
        );
        assert_eq!(
            in_grid, stored,
            "every GLASS BALL photon lands on the floor grid"
        );
        if build == "bitonic" {
            assert_eq!(in_map, in_grid);
        } else {
            assert!(in_map <= in_grid && in_map > in_grid * 9 / 10, "{v}");
        }
    }
}

#[test]
fn the_hash_grid_reaches_photons_and_its_limits_are_named() {
    let uniform = photons_json("glass_ball", &["--build", "stencil"]);
    let hashed = photons_json("glass_ball", &["--build", "stencil", "--grid", "hash"]);
    assert_eq!(uniform["grid_storage"], "uniform");
    assert_eq!(
        hashed["grid_storage"]["hashed"]["buckets"], 8192,
        "{hashed}"
    );
    assert!(hashed["grid_texels"].as_u64() < uniform["grid_texels"].as_u64());
    let lost = hashed["lost_power_fraction"].as_f64().unwrap();
    assert!((0.0..0.01).contains(&lost), "{hashed}");
    let refused = |args: &[&str], says: &str| {
        let out = photonmap()
            .args(["photons"])
            .args(args)
            .arg(scene("ring"))
            .output()
            .unwrap();
        assert!(!out.status.success());
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(says), "{err}");
        assert!(!err.contains("panicked"), "{err}");
    };
    refused(&["--grid", "hash", "--hash-buckets", "0"], "1..=16777216");
    refused(
        &["--set", "photon_map.grid_resolution=[1025,1,1]"],
        "1..=1024",
    );
    refused(
        &["--set", "photon_map.grid_resolution=[1024,1024,1024]"],
        "--grid hash",
    );
}

#[test]
fn faithful_photons_match_the_default_ones() {
    let a = photons_json("cornell_box", &["--build", "stencil"]);
    let b = photons_json("cornell_box", &["--build", "stencil", "--faithful"]);
    // The random texture holds the hash's numbers: the same photons, the same map.
    for field in ["attempts", "emitted", "photons_used", "stored"] {
        assert_eq!(a["trace"][field], b["trace"][field], "{field}");
    }
    assert_eq!(a["photons_in_map"], b["photons_in_map"]);
    assert!(b["timings"]["stages"]
        .as_array()
        .unwrap()
        .iter()
        .any(|s| s["name"] == "read-back (wall)"));
}

#[test]
fn bench_build_prints_json_rows() {
    let out = photonmap()
        .args([
            "bench",
            "build",
            "--json",
            "--quiet",
            "--min-log2",
            "10",
            "--max-log2",
            "11",
        ])
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["bitonic_passes"], 55);
    assert_eq!(rows[1]["bitonic_passes"], 66);
    assert!(rows[0]["copy_pass_seconds"].as_f64().unwrap() > 0.0);
    let bad = photonmap()
        .args(["bench", "build", "--min-log2", "30"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("allowed range"));
}

#[test]
fn snapshots_record_the_running_estimate_and_end_with_the_final_image() {
    let d = tmp("snapshots");
    let snaps = d.join("snaps");
    std::fs::create_dir_all(&snaps).unwrap();
    let png = d.join("final.png");
    let out = photonmap()
        .args([
            "render", "--quiet", "--width", "64", "--height", "48", "--budget", "16", "--every",
            "3",
        ])
        .arg(scene("glass_ball"))
        .arg("-o")
        .arg(&png)
        .arg("--snapshots")
        .arg(&snaps)
        .output()
        .unwrap();
    assert_ok(&out);
    let index: serde_json::Value =
        serde_json::from_slice(&std::fs::read(snaps.join("snapshots.json")).unwrap()).unwrap();
    let list = index.as_array().unwrap();
    assert!(list.len() >= 3, "{index}");
    let passes: Vec<u64> = list.iter().map(|s| s["pass"].as_u64().unwrap()).collect();
    assert!(passes.windows(2).all(|w| w[1] > w[0]), "{passes:?}");
    for s in list {
        assert!(snaps.join(s["file"].as_str().unwrap()).is_file());
    }
    assert_eq!(list.last().unwrap()["searching_pixels"], 0);
    let last = std::fs::read(snaps.join(list.last().unwrap()["file"].as_str().unwrap())).unwrap();
    assert_eq!(
        last,
        std::fs::read(&png).unwrap(),
        "the last snapshot is the final image"
    );
    let first = std::fs::read(snaps.join(list[0]["file"].as_str().unwrap())).unwrap();
    assert_ne!(first, last, "the running estimate changes");
    let bad = photonmap()
        .args(["render", "--every", "0"])
        .arg(scene("ring"))
        .arg("-o")
        .arg(d.join("x.png"))
        .arg("--snapshots")
        .arg(&snaps)
        .output()
        .unwrap();
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains("--every"));
}

#[test]
fn bench_mask_reports_each_masking() {
    let out = photonmap()
        .args([
            "bench",
            "mask",
            "--json",
            "--size",
            "64",
            "--iterations",
            "5",
        ])
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert!(rows
        .iter()
        .all(|r| r["wall_seconds"].as_f64().unwrap() > 0.0));
}

#[test]
fn tables_quick_produces_every_table_with_sane_values() {
    let d = tmp("tables");
    let out = photonmap()
        .args(["tables", "--quick", "--json", "--quiet", "--out"])
        .arg(&d)
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    // Table 1: 3 scenes x 2 builds x 4 stages, positive times, the paper's figures beside them.
    let t1 = v["table1"].as_array().unwrap();
    assert_eq!(t1.len(), 24);
    for c in t1 {
        let s = c["median_wall_seconds"].as_f64().unwrap();
        assert!(s > 0.0 && s < 120.0, "{c}");
        assert!(c["paper_seconds"].as_f64().unwrap() > 0.0);
        assert!(
            (c["ratio_to_paper"].as_f64().unwrap() - s / c["paper_seconds"].as_f64().unwrap())
                .abs()
                < 1e-9
        );
    }
    assert_eq!(v["totals"].as_array().unwrap().len(), 6);
    // Section 3.3: both scenes, every mode converged in the same number of passes.
    let conv = v["convergence"].as_array().unwrap();
    assert_eq!(conv.len(), 6);
    for scene in ["GLASS BALL", "CORNELL BOX"] {
        let passes: Vec<u64> = conv
            .iter()
            .filter(|c| c["scene"] == scene)
            .map(|c| c["passes"].as_u64().unwrap())
            .collect();
        assert!(
            passes.iter().all(|&p| p == passes[0] && p > 0),
            "{scene}: {passes:?}"
        );
    }
    // Passes against n: k (k + 1) / 2.
    for row in v["passes"].as_array().unwrap() {
        let n = row["photons"].as_u64().unwrap();
        let k = 63 - n.leading_zeros() as u64;
        assert_eq!(row["bitonic_passes"].as_u64().unwrap(), k * (k + 1) / 2);
    }
    // Figures 7 and 8 exist; visual convergence comes no later than full convergence.
    for f in [
        "figure7.png",
        "figure8.png",
        "tables.md",
        "table1.csv",
        "results.json",
    ] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    for scene in ["glass_ball", "ring", "cornell_box"] {
        for kind in ["bitonic", "stencil", "software"] {
            assert!(
                d.join("figure7")
                    .join(format!("{scene}_{kind}.png"))
                    .is_file(),
                "{scene}_{kind}"
            );
        }
    }
    let f8 = &v["figure8"];
    assert!(
        f8["visual_convergence_seconds"].as_f64().unwrap()
            <= f8["full_convergence_seconds"].as_f64().unwrap()
    );
    // Table 2: five kernels with counts (CI installs glslang-tools; elsewhere it may be missing).
    match v["table2"].get("Ok") {
        Some(rows) => {
            let rows = rows.as_array().unwrap();
            assert_eq!(rows.len(), 5);
            assert!(rows.iter().all(|r| r["instructions"].as_u64().unwrap() > 10
                && r["texture_fetches"].as_u64().unwrap() >= 1));
        }
        None => {
            assert!(
                std::env::var_os("CI").is_none(),
                "Table 2 missing in CI: {}",
                v["table2"]
            );
            assert!(v["table2"]["Err"].as_str().unwrap().contains("glslang"));
        }
    }
}

#[test]
fn compare_prints_metrics_writes_a_difference_image_and_checks_its_inputs() {
    let d = tmp("compare");
    let render_exr = |seed: &str, name: &str| {
        let exr = d.join(name);
        let st = photonmap()
            .args([
                "render",
                "--quiet",
                "--direct-only",
                "--width",
                "40",
                "--height",
                "30",
                "--seed",
                seed,
            ])
            .arg(scene("glass_ball"))
            .arg("-o")
            .arg(d.join("x.png"))
            .arg("--exr")
            .arg(&exr)
            .status()
            .unwrap();
        assert!(st.success());
        exr
    };
    let (a, b) = (render_exr("1", "a.exr"), render_exr("2", "b.exr"));
    let metrics = |x: &PathBuf, y: &PathBuf, extra: &[&str]| {
        let out = photonmap()
            .arg("compare")
            .arg(x)
            .arg(y)
            .arg("--json")
            .args(extra)
            .output()
            .unwrap();
        assert_ok(&out);
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()
    };
    let same = metrics(&a, &a, &[]);
    assert_eq!(same["rmse"], 0.0);
    assert_eq!(same["ssim"], 1.0);
    let diff_png = d.join("diff.png");
    let other = metrics(&a, &b, &["--diff", diff_png.to_str().unwrap()]);
    assert!(
        other["rmse"].as_f64().unwrap() > 0.0 && other["ssim"].as_f64().unwrap() < 1.0,
        "{other}"
    );
    assert_eq!(
        image::open(&diff_png).unwrap().to_rgb8().dimensions(),
        (40, 30)
    );
    // A mask of the wrong size is refused, naming both sizes.
    let small = d.join("mask.png");
    image::RgbImage::new(10, 10).save(&small).unwrap();
    let out = photonmap()
        .arg("compare")
        .arg(&a)
        .arg(&b)
        .arg("--mask")
        .arg(&small)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("10 x 10"));
    let missing = photonmap()
        .arg("compare")
        .arg(d.join("nope.exr"))
        .arg(&b)
        .output()
        .unwrap();
    assert!(
        !missing.status.success() && String::from_utf8_lossy(&missing.stderr).contains("nope.exr")
    );
}

#[test]
fn reference_and_accuracy_bench_write_their_results() {
    let d = tmp("accuracy");
    let reference = d.join("gb.sppm.exr");
    let out = photonmap()
        .args([
            "reference",
            "--scale",
            "8",
            "--iterations",
            "8",
            "--photons-per-iteration",
            "4096",
            "--quiet",
            "--out",
        ])
        .arg(&reference)
        .arg(scene("glass_ball"))
        .output()
        .unwrap();
    assert_ok(&out);
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
    let out = photonmap()
        .args([
            "bench", "accuracy", "--quick", "--quiet", "--json", "--scene",
        ])
        .arg(scene("glass_ball"))
        .arg("--reference")
        .arg(&reference)
        .arg("--out")
        .arg(&results)
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
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
    // Without a reference it says how to make one.
    let none = photonmap()
        .args(["bench", "accuracy", "--scene"])
        .arg(scene("ring"))
        .args(["--reference"])
        .arg(d.join("none.exr"))
        .output()
        .unwrap();
    assert!(
        !none.status.success()
            && String::from_utf8_lossy(&none.stderr).contains("photonmap reference")
    );
}

/// `bench accuracy --only` runs the matching rows; matching none is an error
/// that lists them.
fn accuracy_only_runs_the_matching_rows(reference: &Path, out: &Path) {
    let only = |texts: &[&str]| {
        photonmap()
            .args([
                "bench", "accuracy", "--quiet", "--json", "--seeds", "2", "--scene",
            ])
            .arg(scene("glass_ball"))
            .arg("--reference")
            .arg(reference)
            .arg("--out")
            .arg(out)
            .args(texts.iter().flat_map(|t| ["--only", t]))
            .output()
            .unwrap()
    };
    let one = only(&["k x2", "k x0.5"]);
    let v: serde_json::Value = serde_json::from_slice(&one.stdout).unwrap();
    assert_eq!(v["runs"].as_array().unwrap().len(), 2, "{v}");
    assert!(
        v["bias_map_scale"].is_null(),
        "no defaults run, no bias map"
    );
    let none = only(&["no such run"]);
    assert!(
        !none.status.success()
            && String::from_utf8_lossy(&none.stderr).contains("scene defaults, photons x")
    );
}

/// A user who moves a scene far from the origin in its file sees the same
/// image, and no warning: the loader reads points in f64 and rebases the
/// scene to its centre before anything is f32. (Loaded in f32, RING moved by
/// 1e4 measured a relative MSE of 0.0098 against twice the seed-to-seed
/// 0.0044 in the stress suite, and warned.) A scene whose parts are far from
/// each other (here the camera, 2e4 away) still warns: rebasing cannot help it.
#[test]
fn far_from_the_origin_a_scene_renders_as_near_it_without_warning() {
    let d = tmp("far");
    let original = std::fs::read_to_string(scene("ring")).unwrap();
    let (text, points) = common::moved_scene_text(&original, glam::DVec3::new(1e4, -1e4, 1e4));
    assert_eq!(
        points, 7,
        "RING's points: camera 2, grid 2, floor, cylinder, light"
    );
    let far = d.join("far.toml");
    std::fs::write(&far, text).unwrap();
    let render = |file: &std::path::Path, seed: &str, out: &str| {
        let out = d.join(out);
        let o = photonmap()
            .args(["render", "--width", "64", "--height", "48", "--seed", seed])
            .arg(file)
            .arg("-o")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        assert!(o.status.success(), "{err}");
        (Image::read_exr(&out).unwrap(), err)
    };
    let (moved, moved_err) = render(&far, "1", "moved.exr");
    let (near, near_err) = render(&scene("ring"), "1", "near.exr");
    let (other_seed, _) = render(&scene("ring"), "2", "seed2.exr");
    assert!(!moved_err.contains("warning"), "{moved_err}");
    assert!(!near_err.contains("warning"), "{near_err}");
    let rel = |a: &Image, b: &Image| photonmap::metrics::compare(a, b, None).unwrap().rel_mse;
    let (e, noise) = (rel(&moved, &near), rel(&other_seed, &near));
    eprintln!("moved by 1e4: relative MSE {e:e}; seed to seed {noise:e}");
    // The moved file's points differ from the original's by t plus the
    // rounding of its decimal text in f64 (~1e-12); the centre, rounded to a
    // power of two, is moved back by exactly t, so the f32 scene is the
    // original's but for an ulp where that 1e-12 crosses an f32 rounding
    // boundary. Such a difference moves a few photons, far below the noise of
    // another seed: a thousandth of it allows that, and nothing visible.
    assert!(e <= 1e-3 * noise, "{e} against seed-to-seed {noise}");

    let (spread, warned) = {
        let text = original
            .replace(
                "position = [0.0, 3.2, 3.2]",
                "position = [20000.0, 3.2, 3.2]",
            )
            .replace("look_at = [0.0, 0.0, 0.1]", "look_at = [20000.0, 0.0, 0.1]");
        let f = d.join("spread.toml");
        std::fs::write(&f, text).unwrap();
        let o = photonmap()
            .args(["render", "--direct-only", "--width", "8", "--height", "6"])
            .arg(&f)
            .arg("-o")
            .arg(d.join("spread.png"))
            .output()
            .unwrap();
        (
            o.status.success(),
            String::from_utf8_lossy(&o.stderr).into_owned(),
        )
    };
    assert!(spread);
    assert!(warned.contains("warning: coordinates reach"), "{warned}");
}

#[test]
fn a_camera_path_renders_every_frame_on_one_photon_map() {
    let d = tmp("path");
    let path = d.join("path.toml");
    std::fs::write(&path, "frames = 3\n[[key]]\nposition = [0.0, 2.0, 5.5]\nlook_at = [0.0, 0.6, 0.0]\n[[key]]\nposition = [3.0, 1.5, 3.0]\nlook_at = [0.0, 0.4, 0.0]\n").unwrap();
    let frames = d.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let out = photonmap()
        .args([
            "render",
            "--width",
            "48",
            "--height",
            "36",
            "--explain",
            "--camera-path",
        ])
        .arg(&path)
        .arg("--out")
        .arg(&frames)
        .arg(scene("glass_ball"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    for i in 0..3 {
        assert!(
            frames.join(format!("frame_{i:04}.png")).is_file(),
            "frame {i}"
        );
    }
    // One photon trace and one map for the three frames, three estimates.
    assert_eq!(err.matches("run  trace photons").count(), 1, "{err}");
    assert_eq!(err.matches("run  radiance estimate").count(), 3, "{err}");
    let first = std::fs::read(frames.join("frame_0000.png")).unwrap();
    assert_ne!(
        first,
        std::fs::read(frames.join("frame_0002.png")).unwrap(),
        "the camera moved"
    );
    // The first key is the scene's own camera: frame 0 is the plain render.
    let single = d.join("single.png");
    assert!(photonmap()
        .args(["render", "--quiet", "--width", "48", "--height", "36"])
        .arg(scene("glass_ball"))
        .arg("-o")
        .arg(&single)
        .status()
        .unwrap()
        .success());
    assert_eq!(first, std::fs::read(&single).unwrap());
    // Bad paths are refused by name.
    std::fs::write(
        &path,
        "[[key]]\nposition = [0.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\n",
    )
    .unwrap();
    let bad = photonmap()
        .args(["render", "--camera-path"])
        .arg(&path)
        .arg("--out")
        .arg(&frames)
        .arg(scene("glass_ball"))
        .output()
        .unwrap();
    assert!(!bad.status.success() && String::from_utf8_lossy(&bad.stderr).contains("key[0]"));
}

/// RING stores caustics only: `photons` and `--explain` say its photons are
/// aimed by projection maps, and `--no-projection-map` emits everywhere,
/// needing many more photons for the same stored count.
#[test]
fn projection_maps_are_reported_and_can_be_switched_off() {
    let aimed = photons_json("ring", &[]);
    let everywhere = photons_json("ring", &["--no-projection-map"]);
    assert_eq!(aimed["trace"]["target"], 16000);
    assert_eq!(everywhere["trace"]["target"], 16000);
    let kept = aimed["trace"]["projection"]["kept_power_fraction"]
        .as_f64()
        .unwrap();
    assert!(kept > 0.0 && kept < 0.1, "{aimed}");
    assert!(everywhere["trace"]["projection"].is_null(), "{everywhere}");
    let used = |v: &serde_json::Value| v["trace"]["photons_used"].as_f64().unwrap();
    // About 1 / kept as many photons emitted everywhere; at least half that.
    assert!(
        used(&everywhere) > 0.5 * used(&aimed) / kept,
        "aimed {}, everywhere {}",
        used(&aimed),
        used(&everywhere)
    );

    let explain = |name: &str, extra: &[&str]| -> String {
        let out = photonmap()
            .args(["render", "--quiet", "--explain", "--width", "32"])
            .args(["--height", "24", "-o"])
            .arg(tmp(&format!("projection-{name}")).join("x.png"))
            .args(extra)
            .arg(scene(name))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(out.status.success(), "{err}");
        err
    };
    assert!(explain("ring", &[]).contains("run  projection maps"));
    assert!(explain("ring", &["--no-projection-map"]).contains("skip projection maps"));
    let err = explain("glass_ball", &[]);
    assert!(
        err.contains("skip projection maps") && err.contains("indirect diffuse"),
        "{err}"
    );
}

/// The installed binary, away from its source tree: a paper scene renders by
/// name, `scenes` lists the embedded scenes, and the quick stress suite runs
/// every one of its cases (none may be skipped or fail to run).
#[test]
fn the_binary_alone_renders_by_name_lists_scenes_and_runs_the_stress_suite() {
    let d = tmp("alone");
    let bin = d.join("photonmap");
    std::fs::copy(env!("CARGO_BIN_EXE_photonmap"), &bin).unwrap();
    let run = |args: &[&str]| {
        let out = Command::new(&bin)
            .args(args)
            .current_dir(&d)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        out
    };
    run(&[
        "render", "ring", "-o", "ring.png", "--quiet", "--width", "64", "--height", "48",
    ]);
    assert_eq!(image::open(d.join("ring.png")).unwrap().width(), 64);
    let listed = String::from_utf8_lossy(&run(&["scenes"]).stdout).to_string();
    for name in [
        "glass_ball",
        "ring",
        "cornell_box",
        "variants/furnace_64_bounces",
    ] {
        assert!(listed.contains(name), "{listed}");
    }
    let out = run(&["bench", "stress", "--quick", "--json", "--quiet"]);
    let mut cases: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
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
    let bad = Command::new(&bin)
        .args(["render", "no_such_scene", "-o", "x.png"])
        .current_dir(&d)
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("no_such_scene"));
}

/// `--mask 0` is refused with the range (it used to become 1 silently), and a
/// fly-through reports no made-up output file.
#[test]
fn mask_zero_is_refused_and_camera_paths_need_no_output_image() {
    let d = tmp("mask0");
    let out = photonmap()
        .args(["render", "--quiet", "--mask", "0"])
        .arg(scene("ring"))
        .arg("-o")
        .arg(d.join("x.png"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("1..=100000"));
    let frames = d.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    let out = photonmap()
        .args(["render", "--width", "32", "--height", "24"])
        .arg(scene("glass_ball"))
        .arg("--camera-path")
        .arg(common::root().join("scenes/paths/glass_ball_orbit.toml"))
        .arg("--out")
        .arg(&frames)
        .output()
        .unwrap();
    assert_ok(&out);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("frames.png"), "{err}");
    assert!(!frames.join("frames.png").exists());
    assert!(frames.join("frame_0000.png").is_file());
}

/// Outputs by extension, several at once; the EXR carries the provenance.
#[test]
fn outputs_by_extension_all_at_once_with_provenance() {
    let d = tmp("outputs");
    let (png, exr, pfm) = (d.join("a.png"), d.join("a.exr"), d.join("a.pfm"));
    let out = photonmap()
        .args([
            "render", "ring", "--quiet", "--json", "--width", "32", "--height", "24",
        ])
        .args(["--set", "photon_map.k=8"])
        .arg("-o")
        .arg(&png)
        .arg("-o")
        .arg(&exr)
        .arg("-o")
        .arg(&pfm)
        .output()
        .unwrap();
    assert_ok(&out);
    let linear = Image::read_exr(&exr).unwrap();
    assert_eq!((linear.width, linear.height), (32, 24));
    assert!(image::open(&png).is_ok());
    let pfm_bytes = std::fs::read(&pfm).unwrap();
    assert!(pfm_bytes.starts_with(b"PF\n32 24\n-1.0\n"));
    assert_eq!(pfm_bytes.len(), "PF\n32 24\n-1.0\n".len() + 32 * 24 * 12);
    let header = Image::exr_attributes(&exr).unwrap();
    assert_eq!(header.len(), 1, "{header:?}");
    assert_eq!(header[0].0, "photonmap.provenance");
    let h: serde_json::Value = serde_json::from_str(&header[0].1).unwrap();
    assert_eq!(h["scene"], "ring");
    assert_eq!(h["overrides"][0], "photon_map.k=8");
    assert!(h["renderer"].as_str().unwrap().contains("llvmpipe"));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["provenance"]["overrides"][0], "photon_map.k=8");
    assert_eq!(v["provenance"]["seed"], 1);
    assert_eq!(v["outputs"].as_array().unwrap().len(), 3);
    assert!(v["provenance"]["scene_hash"].as_str().unwrap().len() == 16);
    // `-o x.exr` alone works, and --set changes the image.
    let plain = d.join("plain.exr");
    let out = photonmap()
        .args([
            "render", "ring", "--quiet", "--width", "32", "--height", "24", "-o",
        ])
        .arg(&plain)
        .output()
        .unwrap();
    assert_ok(&out);
    assert_ne!(
        Image::read_exr(&plain).unwrap(),
        linear,
        "--set photon_map.k=8 changed nothing"
    );
    // A bad override is refused like a bad file, naming the override.
    let bad = photonmap()
        .args(["render", "ring", "--set", "photon_map.k=0", "-o"])
        .arg(d.join("bad.png"))
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(
        err.contains("--set photon_map.k") && err.contains("1..=4096"),
        "{err}"
    );
}

/// The leftover-file cases: an output that cannot be written is found before
/// rendering and nothing at all is written (not even the other outputs).
#[test]
fn an_output_that_cannot_be_written_leaves_nothing() {
    let d = tmp("leftover");
    std::fs::create_dir_all(d.join("isdir.exr")).unwrap();
    let out = photonmap()
        .args([
            "render", "ring", "--quiet", "--width", "16", "--height", "12", "-o",
        ])
        .arg(d.join("ok.png"))
        .arg("--exr")
        .arg(d.join("isdir.exr"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("isdir.exr"), "{err}");
    assert!(!d.join("ok.png").exists(), "ok.png was left behind");
    // A folder that takes no new file: refused before any rendering.
    let ro = d.join("read-only");
    std::fs::create_dir_all(&ro).unwrap();
    let mut perms = std::fs::metadata(&ro).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&ro, perms).unwrap();
    let root = std::fs::File::create(ro.join("probe")).is_ok(); // root ignores the mode
    if !root {
        let out = photonmap()
            .args(["render", "ring", "--quiet", "-o"])
            .arg(ro.join("x.png"))
            .arg("-o")
            .arg(d.join("y.png"))
            .output()
            .unwrap();
        assert!(!out.status.success());
        assert!(!d.join("y.png").exists());
    }
    let entries: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(entries.len(), 2, "only the two folders: {entries:?}");
}

/// A full disk while writing: on a tiny tmpfs (where root may mount one) the
/// write fails with a clear error, leaves no partial file, and the previous
/// output stays intact.
#[test]
fn a_full_disk_leaves_no_partial_file_and_keeps_the_previous_output() {
    let d = tmp("fulldisk");
    let mnt = d.join("tiny");
    std::fs::create_dir_all(&mnt).unwrap();
    let mounted = Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=48k", "tmpfs"])
        .arg(&mnt)
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        // The failing-writer unit test (photonmap::image) covers the same path.
        eprintln!("no tmpfs could be mounted here: the full-disk case is the unit test's");
        return;
    }
    let previous = b"previous output";
    std::fs::write(mnt.join("big.exr"), previous).unwrap();
    let out = photonmap()
        .args([
            "render", "ring", "--quiet", "--width", "160", "--height", "120", "-o",
        ])
        .arg(mnt.join("big.exr"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    let left: Vec<_> = std::fs::read_dir(&mnt)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    let kept = std::fs::read(mnt.join("big.exr")).unwrap();
    let _ = Command::new("umount").arg(&mnt).status();
    assert!(
        !out.status.success(),
        "a 160 x 120 float image fit in 48 KiB?"
    );
    assert!(err.contains("No space left"), "{err}");
    assert_eq!(left.len(), 1, "{left:?}");
    assert_eq!(kept, previous);
}

/// compare as a CI gate: an identical image passes, a perturbed one fails
/// with exit code 1 and a difference image.
#[test]
fn compare_fails_a_perturbed_image_and_passes_an_identical_one() {
    let d = tmp("gate");
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    let render = |path: &std::path::Path, extra: &[&str]| {
        let out = photonmap()
            .args([
                "render",
                "glass_ball",
                "--quiet",
                "--width",
                "48",
                "--height",
                "36",
            ])
            .args(extra)
            .arg("-o")
            .arg(path)
            .output()
            .unwrap();
        assert_ok(&out);
    };
    render(&a, &[]);
    render(&b, &["--set", "light[0].radiance=[80.0, 80.0, 80.0]"]);
    let gate = |image: &std::path::Path| {
        photonmap()
            .args([
                "compare",
                "--json",
                "--fail-rmse",
                "0.01",
                "--fail-ssim",
                "0.99",
                "--fail-flip",
                "0.05",
            ])
            .args(["--fail", "0.05", "--fail-percent", "1"])
            .arg(image)
            .arg(&a)
            .arg("--diff")
            .arg(d.join("diff.png"))
            .output()
            .unwrap()
    };
    let same = gate(&a);
    assert_eq!(
        same.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&same.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&same.stdout).unwrap();
    assert_eq!(v["passed"], true);
    assert_eq!(v["flip"], 0.0);
    let _ = std::fs::remove_file(d.join("diff.png"));
    let changed = gate(&b);
    assert_eq!(changed.status.code(), Some(1));
    let v: serde_json::Value = serde_json::from_slice(&changed.stdout).unwrap();
    assert_eq!(v["passed"], false);
    let failed: Vec<&str> = v["checks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| c["passed"] == false)
        .map(|c| c["metric"].as_str().unwrap())
        .collect();
    assert!(
        failed.contains(&"rmse") && failed.contains(&"percent_beyond"),
        "{v}"
    );
    assert!(
        d.join("diff.png").is_file(),
        "the difference image is written on failure"
    );
}

/// regress passes the scene as it is and catches the three defects the
/// regression test catches (a 10% brighter light, the camera one pixel off,
/// the caustic missing), with a JSON verdict, JUnit XML and images on failure.
#[test]
fn regress_catches_a_brighter_light_a_shifted_camera_and_a_missing_caustic() {
    let d = tmp("regress");
    let run = |label: &str, extra: &[&str]| {
        let junit = d.join(format!("{label}.xml"));
        let out = photonmap()
            .args([
                "regress",
                "scenes/ring.toml",
                "--reference",
                "reference_images",
                "--json",
            ])
            .args(extra)
            .arg("--junit")
            .arg(&junit)
            .arg("--out")
            .arg(d.join(label))
            .current_dir(common::root())
            .output()
            .unwrap();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|_| panic!("{label}: {}", String::from_utf8_lossy(&out.stderr)));
        let xml = std::fs::read_to_string(&junit).unwrap();
        (out.status.code(), v, xml)
    };
    let (code, v, xml) = run("as_is", &[]);
    assert_eq!(code, Some(0), "{v}");
    assert!(xml.contains("failures=\"0\""), "{xml}");
    // One pixel to the right at the reference's 96 rows: 2 d tan(vfov / 2) / 96.
    let dist = (3.2f32 * 3.2 + 3.1 * 3.1).sqrt();
    let pixel = 2.0 * dist * (17.5f32.to_radians()).tan() / 96.0;
    let position = format!("camera.position=[{pixel}, 3.2, 3.2]");
    let look_at = format!("camera.look_at=[{pixel}, 0.0, 0.1]");
    for (label, extra) in [
        (
            "brighter",
            vec!["--set", "light[0].intensity=[44.0, 44.0, 44.0]"],
        ),
        ("shifted", vec!["--set", &position, "--set", &look_at]),
        ("no_caustic", vec!["--direct-only"]),
    ] {
        let (code, v, xml) = run(label, &extra);
        eprintln!(
            "{label}: {:.3}% beyond |z| = 4 (tolerance {:.3}%)",
            100.0 * v["failing_fraction"].as_f64().unwrap(),
            100.0 * v["tolerance"].as_f64().unwrap()
        );
        assert_eq!(code, Some(1), "{label} passed: {v}");
        assert_eq!(v["passed"], false);
        assert!(xml.contains("<failure"), "{xml}");
        for f in ["actual.exr", "reference.exr", "z.png"] {
            assert!(d.join(label).join(f).is_file(), "{label}: {f}");
        }
    }
}

/// The same seed gives the same image whatever llvmpipe's thread count.
#[test]
fn threads_do_not_change_the_image() {
    let d = tmp("threads");
    for n in ["1", "2", "3"] {
        let out = photonmap()
            .args([
                "render",
                "glass_ball",
                "--quiet",
                "--width",
                "48",
                "--height",
                "36",
                "--threads",
                n,
                "-o",
            ])
            .arg(d.join(format!("t{n}.exr")))
            .output()
            .unwrap();
        assert_ok(&out);
    }
    let one = std::fs::read(d.join("t1.exr")).unwrap();
    for n in ["2", "3"] {
        assert_eq!(
            std::fs::read(d.join(format!("t{n}.exr"))).unwrap(),
            one,
            "--threads {n}"
        );
    }
}

#[test]
fn bench_meshes_reports_every_size_with_rates_renders_and_a_plot() {
    let d = tmp("meshes");
    let out = photonmap()
        .args([
            "bench",
            "meshes",
            "--triangles",
            "8,2000",
            "--width",
            "48",
            "--height",
            "32",
            "--photons",
            "4096",
            "--json",
            "--out",
        ])
        .arg(&d)
        .output()
        .unwrap();
    assert_ok(&out);
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = report["rows"].as_array().unwrap();
    // The analytic ball, then the meshes as generated (the UV sphere rounds the count).
    let triangles: Vec<u64> = rows
        .iter()
        .map(|r| r["triangles"].as_u64().unwrap())
        .collect();
    assert_eq!(triangles[0], 0);
    assert_eq!(triangles[1], 8);
    assert!((1800..2200).contains(&triangles[2]), "{triangles:?}");
    for r in rows {
        for rate in [
            "eye_rays_per_second",
            "shadow_rays_per_second",
            "photon_rays_per_second",
        ] {
            assert!(r[rate].as_f64().unwrap() > 0.0, "{rate}: {r}");
        }
        assert!(r["render_seconds"].as_f64().unwrap() > 0.0);
        assert!(r["bvh_depth"].as_u64().unwrap() >= 1);
    }
    assert_eq!(rows[0]["rays"]["eye_rays"], 48 * 32);
    assert!(report["provenance"]["renderer"].as_str().is_some());
    for f in [
        "meshes.json",
        "meshes.svg",
        "render_analytic.png",
        "render_8.png",
    ] {
        assert!(d.join(f).is_file(), "{f} missing");
    }
    let bad = photonmap()
        .args(["bench", "meshes", "--triangles", "4"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("8"));
}

/// Final gather and adaptive sampling as a user runs them: the JSON reports
/// the gather and the pyramid's levels (adaptive SPPM: its pilot and plan); a
/// caustics-only scene, final gather with SPPM, a pilot that leaves no
/// iterations, and --gather-k, a threshold or a pilot without their switch
/// are refused with a reason, and write nothing.
#[test]
fn final_gather_and_adaptive_sampling_run_and_refuse_what_they_cannot_do() {
    let d = tmp("final-gather");
    let json = render_cornell_box_json(
        &d,
        ["40", "36"],
        &[
            "--final-gather",
            "3",
            "--adaptive",
            "--set",
            "photon_map.photons_stored=4000",
        ],
    );
    assert_eq!(json["method"], "final-gather");
    assert_eq!(json["final_gather"]["rays"], 3);
    assert_eq!(json["gathers"][0]["rays_per_pixel"], 3);
    let levels = json["adaptive_samples"][0]["levels"].as_array().unwrap();
    assert_eq!(levels.len(), 4, "{levels:?}");
    let computed = json["adaptive_samples"][0]["computed"].as_u64().unwrap();
    let all = json["adaptive_samples"][0]["pixels_with_hits"]
        .as_u64()
        .unwrap();
    assert!(0 < computed && computed < all, "{computed} of {all}");
    let json = render_cornell_box_json(
        &d,
        ["40", "36"],
        &[
            "--method",
            "sppm",
            "--adaptive",
            "--iterations",
            "4",
            "--photons-per-iteration",
            "4096",
        ],
    );
    assert_eq!(
        json["adaptive_pilot"], 1,
        "an eighth of 4 iterations, at least 1"
    );
    let interpolated = json["adaptive_samples"]["interpolated"].as_u64().unwrap();
    assert!(0 < interpolated && interpolated < 40 * 36, "{interpolated}");
    let refused: [(&[&str], &str); 13] = [
        (
            &["--adaptive", "--method", "sppm", "--sppm-direct", "photons"],
            "shadow-rays",
        ),
        (
            &["--final-gather", "2", "--scene-name-ring"],
            "caustics_only",
        ),
        (&["--adaptive", "--snapshots", "."], "--snapshots"),
        (
            &["--final-gather", "2", "--reference-software", "r.png"],
            "--reference-software",
        ),
        (
            &[
                "--adaptive",
                "--method",
                "sppm",
                "--iterations",
                "4",
                "--adaptive-pilot",
                "4",
            ],
            "pilot",
        ),
        (&["--adaptive", "--adaptive-pilot", "2"], "--adaptive-pilot"),
        (&["--method", "sppm", "--adaptive-pilot", "2"], "--adaptive"),
        (
            &["--final-gather", "2", "--method", "sppm"],
            "--final-gather",
        ),
        (&["--gather-k", "10"], "--final-gather"),
        (&["--adaptive-threshold", "0.2"], "--adaptive"),
        (
            &["--method", "sppm", "--start-photons", "70000"],
            "0..=65536",
        ),
        (
            &["--method", "sppm", "--start-pixels=-1"],
            "0..=1000000 (0: no bound)",
        ),
        (
            &["--method", "sppm", "--start-pixels", "2", "--radius", "0.1"],
            "--radius",
        ),
    ];
    for (args, says) in refused {
        let ring = args.contains(&"--scene-name-ring");
        let args: Vec<&str> = args
            .iter()
            .copied()
            .filter(|a| !a.starts_with("--scene-name"))
            .collect();
        assert_render_refused(&d, if ring { "ring" } else { "cornell_box" }, &args, says);
    }
}

/// IGI as a user runs it: the JSON reports the VPLs and the gather; IGI's
/// switches without `--method igi`, the one-shot estimate's accelerations
/// with it, and impossible values are refused with a reason, writing nothing.
#[test]
fn igi_runs_and_refuses_what_it_cannot_do() {
    let d = tmp("igi");
    let json = render_cornell_box_json(
        &d,
        ["40", "36"],
        &[
            "--method",
            "igi",
            "--vpl-paths",
            "32",
            "--interleave",
            "2",
            "--downsample",
            "2",
            "--imperfect-visibility",
            "--set",
            "photon_map.photons_stored=4000",
        ],
    );
    assert_eq!(json["method"], "igi");
    assert_eq!(json["vpls"]["paths"], 32);
    let vpls = json["vpls"]["vpls"].as_u64().unwrap();
    assert!(vpls >= 32, "{vpls}");
    assert_eq!(json["igi"]["interleave"], 2);
    let per_point = json["igi_samples"][0]["vpls_per_point"].as_f64().unwrap();
    assert_eq!(per_point, vpls as f64 / 4.0);
    let refused: [(&[&str], &str); 7] = [
        (&["--interleave", "3"], "--method igi"),
        (&["--method", "sppm", "--interleave", "3"], "IGI's switches"),
        (&["--method", "igi", "--direct-only"], "--direct-only"),
        (&["--method", "igi", "--adaptive"], "--adaptive"),
        (
            &["--method", "igi", "--final-gather", "2"],
            "--final-gather",
        ),
        (&["--method", "igi", "--interleave", "0"], "1..=8"),
        (&["--method", "igi", "--vpl-min-distance=-1"], "0 or more"),
    ];
    for (args, says) in refused {
        assert_render_refused(&d, "cornell_box", args, says);
    }
}

/// `bench igi` on the mesh stage: the paper's four versions and two remedies,
/// each with its time split into components that add up to it (the stages
/// outside them are few and small), its image, and no reference to compare.
#[test]
fn bench_igi_splits_each_version_by_component() {
    let d = tmp("bench-igi");
    let out = photonmap()
        .args([
            "bench",
            "igi",
            "--triangles",
            "1024",
            "--vpl-paths",
            "16",
            "--json",
            "--quiet",
            "--out",
        ])
        .arg(&d)
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert!(v["reference"].is_null());
    assert_eq!(rows[0]["rmse_to_canonical"], 0.0);
    for r in rows {
        let f = |k: &str| r[k].as_f64().unwrap();
        let parts = f("direct") + f("specular") + f("indirect") + f("caustics") + f("other");
        assert!(parts <= f("seconds") && parts > 0.5 * f("seconds"), "{r}");
        assert!(r["rmse"].is_null());
    }
    assert!(rows[3]["options"]["interleave"] == 3 && rows[3]["options"]["downsample"] == 4);
    assert!(d.join("igi.json").is_file() && d.join("00_igi.png").is_file());
}

/// Photon differentials as a user runs them: the JSON reports the map (its
/// footprints, s chosen by the pilot, the automatic leaf size) and the
/// estimate; their switches without `--method differentials`, the kNN
/// estimate's accelerations with it, and impossible values are refused with
/// a reason, writing nothing.
#[test]
fn differentials_run_and_refuse_what_they_cannot_do() {
    let d = tmp("differentials");
    let json = render_cornell_box_json(
        &d,
        ["40", "36"],
        &[
            "--method",
            "differentials",
            "--kernel",
            "epanechnikov",
            "--set",
            "photon_map.photons_stored=4000",
        ],
    );
    assert_eq!(json["method"], "differentials");
    let map = &json["differentials"];
    assert!(map["footprints"].as_u64().unwrap() >= 4000, "{map}");
    assert_eq!(map["kernel"], "epanechnikov");
    // Auto: s = sqrt((k - caustic) / diffuse), the pilot's means at s = 1,
    // k = 500 in CORNELL BOX.
    let diffuse = map["pilot_mean_diffuse_footprints"].as_f64().unwrap();
    let caustic = map["pilot_mean_footprints"].as_f64().unwrap() - diffuse;
    let s = map["smoothing"].as_f64().unwrap();
    assert!(
        (s - ((500.0 - caustic) / diffuse).sqrt()).abs() < 1e-3 * s,
        "{map}"
    );
    assert_eq!(map["leaf_size"], map["auto_leaf_size"]);
    let sample = &json["footprint_samples"][0];
    assert!(
        sample["mean_footprints"].as_f64().unwrap() > 1.0,
        "{sample}"
    );
    assert!(sample["passes"].as_u64().unwrap() >= 1);
    let refused: [(&[&str], &str); 10] = [
        (&["--leaf-size", "8"], "--method differentials"),
        (&["--method", "differentials", "--grid", "hash"], "--grid"),
        (&["--method", "differentials", "--tile", "8"], "--tile"),
        (
            &["--method", "differentials", "--paper-search"],
            "--paper-search",
        ),
        (
            &["--method", "sppm", "--smoothing", "3"],
            "photon differentials'",
        ),
        (&["--method", "differentials", "--adaptive"], "--adaptive"),
        (
            &["--method", "differentials", "--final-gather", "2"],
            "--final-gather",
        ),
        (
            &["--method", "differentials", "--leaf-size", "0"],
            "1..=1024",
        ),
        (&["--method", "differentials", "--smoothing=0"], "positive"),
        (
            &["--method", "differentials", "--direct-only"],
            "--direct-only",
        ),
    ];
    for (args, says) in refused {
        assert_render_refused(&d, "cornell_box", args, says);
    }
}

/// Radiosity as a user runs it: the JSON reports the patches, the shots and
/// the convergence after each; its switches without `--method radiosity`,
/// the one-map estimate's accelerations with it, and impossible values are
/// refused with a reason, writing nothing.
#[test]
fn radiosity_runs_and_refuses_what_it_cannot_do() {
    let d = tmp("radiosity");
    let json = render_cornell_box_json(
        &d,
        ["32", "32"],
        &[
            "--method",
            "radiosity",
            "--elements",
            "8",
            "--substructure",
            "2",
            "--item-buffer",
            "64",
            "--set",
            "photon_map.photons_stored=2000",
        ],
    );
    assert_eq!(json["method"], "radiosity");
    let r = &json["radiosity"];
    assert_eq!(r["element_resolution"], 8);
    assert_eq!(r["converged"], true);
    let curve = r["convergence"].as_array().unwrap();
    assert_eq!(curve.len() as u64, r["shots"].as_u64().unwrap() + 1);
    let unshot: Vec<f64> = curve
        .iter()
        .map(|p| p["unshot_fraction"].as_f64().unwrap())
        .collect();
    assert!(
        unshot[0] > 0.9 && *unshot.last().unwrap() < 1e-2,
        "{unshot:?}"
    );
    assert!(r["tiles"].as_u64().unwrap() >= r["patches"].as_u64().unwrap());
    let refused: [(&[&str], &str); 8] = [
        (&["--elements", "8"], "--method radiosity"),
        (&["--subdivide", "2"], "--method radiosity"),
        (&["--method", "radiosity", "--subdivide", "7"], "0..=6"),
        (&["--method", "radiosity", "--gradient", "0"], "positive"),
        (&["--method", "radiosity", "--adaptive"], "--adaptive"),
        (
            &[
                "--method",
                "radiosity",
                "--elements",
                "8",
                "--substructure",
                "3",
            ],
            "divisor",
        ),
        (&["--method", "radiosity", "--convergence", "2"], "(0, 1)"),
        (&["--method", "sppm", "--max-shots", "4"], "radiosity"),
    ];
    for (args, says) in refused {
        assert_render_refused(&d, "cornell_box", args, says);
    }
}

/// `bench mitsuba` runs Mitsuba through --python, and says before any render
/// when it cannot; `tables --table1-only` needs --out (it would replace the
/// full run's tables.md).
#[test]
fn bench_mitsuba_and_tables_refuse_what_they_cannot_do() {
    let out = photonmap()
        .args([
            "bench",
            "mitsuba",
            "--scene",
            "glass_ball",
            "--python",
            "/nonexistent/python3",
        ])
        .output()
        .unwrap();
    assert_refused(&out, "/nonexistent/python3");
    let out = photonmap()
        .args(["tables", "--table1-only", "--quiet"])
        .output()
        .unwrap();
    assert_refused(&out, "--table1-only needs --out");
}

/// `bench mitsuba` refuses a budget that is not a positive number of
/// seconds, a --reference or --mask that is not there, a mask of another
/// size, and a --mitsuba-reference that cannot be made, before it runs
/// Mitsuba or writes anything.
#[test]
fn bench_mitsuba_refuses_bad_budgets_references_and_masks() {
    let d = tmp("bench-mitsuba");
    let out_dir = d.join("out");
    let refused: [(&[&str], &str); 10] = [
        (&["--seconds", "0"], "--seconds"),
        (&["--mitsuba-reference", "0"], "--mitsuba-reference"),
        (&["--mitsuba-reference", "10", "--scale", "3"], "--scale 3"),
        (&["--scale", "2"], "--mitsuba-reference"),
        (
            &["--mitsuba-reference", "10", "--reference", "x.exr"],
            "cannot be used with",
        ),
        (
            &[
                "--mitsuba-reference",
                "10",
                "--mask",
                "reference_images/truth/cornell_box_interior_mask.png",
            ],
            "256 x 256",
        ),
        (&["--seconds", "30,-1"], "--seconds"),
        (
            &["--reference", "/nonexistent/truth.exr"],
            "/nonexistent/truth.exr",
        ),
        (
            &["--mask", "/nonexistent/mask.png"],
            "/nonexistent/mask.png",
        ),
        (
            &[
                "--mask",
                "reference_images/truth/cornell_box_interior_mask.png",
            ],
            "256 x 256",
        ),
    ];
    for (args, says) in refused {
        let out = photonmap()
            .args(["bench", "mitsuba", "--scene", "glass_ball", "--quiet"])
            .args(["--python", "/nonexistent/python3", "--out"])
            .arg(&out_dir)
            .args(args)
            .current_dir(common::root())
            .output()
            .unwrap();
        assert_refused(&out, says);
        assert!(!out_dir.exists(), "{args:?} wrote {}", out_dir.display());
    }
}

/// `bench differentials --quick` on RING: both methods, the leaf sizes with
/// the automatic one last, and the footprint scales each beside the
/// kNN-grid at the k_PD they reached; errors against the SPPM reference.
#[test]
fn bench_differentials_compares_methods_leaf_sizes_and_k() {
    let d = tmp("bench-differentials");
    let out = photonmap()
        .args([
            "bench",
            "differentials",
            "--scene",
            "ring",
            "--quick",
            "--json",
            "--quiet",
            "--out",
        ])
        .arg(&d)
        .output()
        .unwrap();
    assert_ok(&out);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let methods = v["methods"].as_array().unwrap();
    assert_eq!(methods[0]["method"], "kNN-grid");
    assert_eq!(methods[1]["method"], "differentials");
    let leaves = v["leaf_sizes"].as_array().unwrap();
    assert_eq!(leaves.len(), 5);
    assert!(leaves[4]["label"]
        .as_str()
        .unwrap()
        .starts_with("leaf size auto"));
    let pairs = v["k_pairs"].as_array().unwrap();
    for pair in pairs.chunks(2) {
        let k_pd = pair[0]["k"].as_f64().unwrap();
        assert_eq!(
            pair[1]["k"].as_f64().unwrap(),
            k_pd.round().max(1.0),
            "{pair:?}"
        );
    }
    for r in methods.iter().chain(leaves).chain(pairs) {
        assert!(r["rmse"].as_f64().unwrap() > 0.0, "{r}");
    }
    assert!(d.join("differentials.json").is_file());
}

/// `render` of CORNELL BOX at the given size with `args` and `--json` into
/// `dir/out.png`: it succeeds, writes the image, and prints this JSON.
fn render_cornell_box_json(
    dir: &std::path::Path,
    [w, h]: [&str; 2],
    args: &[&str],
) -> serde_json::Value {
    let png = dir.join("out.png");
    let out = photonmap()
        .args(["render", "--quiet", "--json", "--width", w, "--height", h])
        .args(args)
        .arg(scene("cornell_box"))
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    assert_ok(&out);
    assert!(png.exists());
    serde_json::from_slice(&out.stdout).unwrap()
}

/// `render` of the named scene at 16 x 16 with `args` into `dir/bad.png`
/// fails, says `says`, and writes no image.
fn assert_render_refused(dir: &std::path::Path, name: &str, args: &[&str], says: &str) {
    let bad = dir.join("bad.png");
    let out = photonmap()
        .args(["render", "--quiet", "--width", "16", "--height", "16"])
        .args(args)
        .arg(scene(name))
        .arg("-o")
        .arg(&bad)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{args:?} ran");
    assert!(stderr.contains(says), "{args:?}: {stderr}");
    assert!(!bad.exists(), "{args:?} wrote an image");
}
