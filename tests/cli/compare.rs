//! `photonmap compare`: metrics, a difference image and checked inputs, and
//! compare as a CI gate (thresholds, exit code 1 on failure).

use std::path::PathBuf;

use crate::common::{Printed, Run, TempDir};

#[test]
fn compare_prints_metrics_writes_a_difference_image_and_checks_its_inputs() {
    let d = TempDir::new("compare");
    let render_exr = |seed: &str, name: &str| {
        let exr = d.join(name);
        Run::new(["render", "--quiet", "--direct-only", "--width", "40"])
            .args(["--height", "30", "--seed", seed])
            .scene("glass_ball")
            .output_to(d.join("x.png"))
            .writing("--exr", &exr)
            .succeeds();
        exr
    };
    let (a, b) = (render_exr("1", "a.exr"), render_exr("2", "b.exr"));
    let metrics = |x: &PathBuf, y: &PathBuf, extra: &[&str]| {
        Run::new(["compare"])
            .arg(x)
            .arg(y)
            .arg("--json")
            .args(extra)
            .json()
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
    Run::new(["compare"])
        .arg(&a)
        .arg(&b)
        .arg("--mask")
        .arg(&small)
        .refused_with("10 x 10");
    Run::new(["compare"])
        .arg(d.join("nope.exr"))
        .arg(&b)
        .refused_with("nope.exr");
    // --region: the energy in a rectangle is the sum of a's pixels there over
    // b's; one outside the image is refused.
    let v = metrics(&a, &b, &["--region", "left half=0:20:0:30"]);
    let (ia, ib) = (
        photonmap::render::Image::read_exr(&a).unwrap(),
        photonmap::render::Image::read_exr(&b).unwrap(),
    );
    let sum = |img: &photonmap::render::Image| -> f64 {
        (0..30)
            .flat_map(|y| (0..20).map(move |x| y * 40 + x))
            .map(|i| img.pixels[i].iter().map(|&c| f64::from(c)).sum::<f64>())
            .sum()
    };
    let region = &v["regions"][0];
    assert_eq!(
        (&region["name"], &region["pixels"]),
        (&"left half".into(), &600.into()),
        "{v}"
    );
    let energy = region["energy"].as_f64().unwrap();
    assert!((energy - sum(&ia) / sum(&ib)).abs() < 1e-9, "{energy}");
    assert!(same.get("regions").is_none(), "{same}");
    Run::new(["compare"])
        .arg(&a)
        .arg(&b)
        .args(["--region", "wide=0:41:0:30"])
        .refused_with("outside the 40 x 30 pixels");
}

/// compare as a CI gate: an identical image passes, a perturbed one fails
/// with exit code 1 and a difference image.
#[test]
fn compare_fails_a_perturbed_image_and_passes_an_identical_one() {
    let d = TempDir::new("gate");
    let (a, b) = (d.join("a.exr"), d.join("b.exr"));
    let render = |path: &std::path::Path, extra: &[&str]| {
        Run::new([
            "render",
            "glass_ball",
            "--quiet",
            "--width",
            "48",
            "--height",
            "36",
        ])
        .args(extra)
        .output_to(path)
        .succeeds();
    };
    render(&a, &[]);
    render(&b, &["--set", "light[0].radiance=[80.0, 80.0, 80.0]"]);
    let gate = |image: &std::path::Path| {
        Run::new([
            "compare",
            "--json",
            "--fail-rmse",
            "0.01",
            "--fail-ssim",
            "0.99",
        ])
        .args([
            "--fail-flip",
            "0.05",
            "--fail",
            "0.05",
            "--fail-percent",
            "1",
        ])
        .arg(image)
        .arg(&a)
        .writing("--diff", d.join("diff.png"))
        .run()
    };
    let same = gate(&a);
    assert_eq!(same.status.code(), Some(0), "{}", same.stderr_text());
    let v = same.json();
    assert_eq!(v["passed"], true);
    assert_eq!(v["flip"], 0.0);
    let _ = std::fs::remove_file(d.join("diff.png"));
    let changed = gate(&b);
    assert_eq!(changed.status.code(), Some(1));
    let v = changed.json();
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

/// The two tiers, as idiff has them: a --warn-* threshold that does not hold
/// prints a warning and exits 0, a --fail-* one exits 1; FLIP's percentiles
/// gate through --fail-flip-percentile P:X; with a FLIP threshold the
/// difference image is FLIP's magma map.
#[test]
fn compare_warns_with_exit_0_and_fails_with_exit_1() {
    let d = TempDir::new("tiers");
    let exr = |seed: &str| {
        let p = d.join(format!("{seed}.exr"));
        Run::new(["render", "glass_ball", "--quiet", "--direct-only"])
            .args(["--width", "40", "--height", "30", "--seed", seed])
            .output_to(&p)
            .succeeds();
        p
    };
    let (a, b) = (exr("1"), exr("2"));
    let compare = |extra: &[String]| {
        Run::new(["compare", "--json"])
            .arg(&a)
            .arg(&b)
            .args(extra)
            .run()
    };
    let base = compare(&[]).json();
    let rmse = base["rmse"].as_f64().unwrap();
    let p99 = base["flip_percentiles"]["p99"].as_f64().unwrap();
    let p50 = base["flip_percentiles"]["p50"].as_f64().unwrap();
    assert!(p99 > p50 && p50 > 0.0, "{base}");
    let s = |v: f64| format!("{v}");
    // (flags, exit code, warned)
    let cases: Vec<(Vec<String>, i32, bool)> = vec![
        (vec!["--warn-rmse".into(), s(rmse / 2.0)], 0, true),
        (vec!["--warn-rmse".into(), s(rmse * 2.0)], 0, false),
        (vec!["--fail-rmse".into(), s(rmse / 2.0)], 1, false),
        (
            vec![
                "--warn-rmse".into(),
                s(rmse / 2.0),
                "--fail-rmse".into(),
                s(rmse * 2.0),
            ],
            0,
            true,
        ),
        (vec!["--warn".into(), "0".into()], 0, true),
        (
            vec!["--warn-flip-percentile".into(), format!("99:{}", p99 * 0.9)],
            0,
            true,
        ),
        (
            vec!["--fail-flip-percentile".into(), format!("99:{}", p99 * 0.9)],
            1,
            false,
        ),
        (
            vec![
                "--fail-flip-percentile".into(),
                format!("99:{}", p99 * 1.01),
            ],
            0,
            false,
        ),
        (
            vec![
                "--fail-flip-percentile".into(),
                format!("50:{}", p50 * 1.01),
            ],
            0,
            false,
        ),
    ];
    for (flags, code, warned) in cases {
        let out = compare(&flags);
        assert_eq!(
            out.status.code(),
            Some(code),
            "{flags:?}: {}",
            out.stderr_text()
        );
        let v = out.json();
        assert_eq!(v["warned"], warned, "{flags:?}: {v}");
        assert_eq!(v["passed"], code == 0, "{flags:?}: {v}");
        assert_eq!(out.stderr_text().contains("warning:"), warned, "{flags:?}");
    }
    for (bad, says) in [("150:0.1", "(0, 100)"), ("99", "P:X"), ("99:2", "[0, 1]")] {
        Run::new(["compare", "--fail-flip-percentile", bad])
            .arg(&a)
            .arg(&b)
            .refused_with(says);
    }
    // A FLIP threshold makes --diff FLIP's error map through magma.
    let diff = d.join("flip.png");
    let out = compare(&[
        "--fail-flip-percentile".into(),
        "99:1".into(),
        "--diff".into(),
        diff.display().to_string(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    let (ia, ib) = (
        photonmap::render::Image::read_exr(&a).unwrap(),
        photonmap::render::Image::read_exr(&b).unwrap(),
    );
    let magma = photonmap::metrics::flip_map(&ia, &ib)
        .unwrap()
        .magma_srgb8();
    assert_eq!(image::open(&diff).unwrap().to_rgb8().into_raw(), magma);
}
