//! `render --method ...` and its switches as a user runs them: final gather
//! and adaptive sampling, IGI, photon differentials and radiosity each report
//! what they did in the JSON, and a switch without its method, an
//! acceleration its method cannot use, or an impossible value is refused
//! with a reason, writing no image.

use std::path::Path;

use crate::common::{Run, TempDir};
use photonmap::render::Image;

/// Final gather and adaptive sampling as a user runs them: the JSON reports
/// the gather and the pyramid's levels (adaptive SPPM: its pilot and plan); a
/// caustics-only scene, final gather with SPPM, a pilot that leaves no
/// iterations, and --gather-k, a threshold or a pilot without their switch
/// are refused with a reason, and write nothing.
#[test]
fn final_gather_and_adaptive_sampling_run_and_refuse_what_they_cannot_do() {
    let d = TempDir::new("final-gather");
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

/// On RING, whose one diffuse surface is the floor, a VPL could light
/// nothing: `--explain` says IGI skips its VPLs, gather and compensation.
#[test]
fn igi_says_it_skips_vpls_that_would_light_nothing() {
    let d = TempDir::new("igi-skip");
    let err = Run::new(["render", "--quiet", "--explain", "--width", "32"])
        .args(["--height", "24", "--method", "igi"])
        .output_to(d.join("x.png"))
        .scene("ring")
        .stderr();
    assert!(
        err.contains("skip IGI VPLs, gather") && err.contains("skip IGI bias compensation"),
        "{err}"
    );
}

/// `--explain` on a scene with no mirror or glass (the closed box) says that
/// radiosity's caustic deposit had nothing to deposit, not that light is
/// missing, and says it is missing where `--shoot-caustics false` leaves it
/// out. It says where the image reads the solution: at each pixel, naming
/// the gather that reads it elsewhere, or where `--gather-rays` rays land.
#[test]
fn radiosity_explains_its_deposit_and_where_it_reads_the_solution() {
    let d = TempDir::new("explain-radiosity");
    let explain = |args: &[&str]| {
        Run::new(["render", "--quiet", "--explain", "--width", "32"])
            .args(["--height", "24", "--method", "radiosity", "--elements", "4"])
            .args(["--convergence", "0.01"])
            .args(args)
            .output_to(d.join("x.png"))
            .scene("tests/closed_box")
            .stderr()
    };
    let err = explain(&[]);
    assert!(
        err.contains("no caustic map's light was there to deposit")
            && !err.contains("is missing")
            && err.contains("(--gather-rays N reads it where rays from the pixel land)"),
        "{err}"
    );
    let err = explain(&["--shoot-caustics", "false"]);
    assert!(err.contains("L S+ D D+ is missing"), "{err}");
    let err = explain(&["--gather-rays", "4"]);
    assert!(
        err.contains("final gather: 4 rays a pixel read the solution where they land"),
        "{err}"
    );
}

/// `--explain` says which footprint photon differentials sum, as
/// `--footprint-shape` asks.
#[test]
fn differentials_explain_which_footprint_they_sum() {
    let d = TempDir::new("explain-differentials");
    let explain = |args: &[&str]| {
        Run::new(["render", "--quiet", "--explain", "--width", "32"])
            .args(["--height", "24", "--method", "differentials"])
            .args(["--set", "photon_map.photons_stored=2000"])
            .args(args)
            .output_to(d.join("x.png"))
            .scene("cornell_box_obj")
            .stderr()
    };
    assert!(explain(&[]).contains("so a curved surface stays in it"));
    let err = explain(&["--footprint-shape", "ellipsoid"]);
    assert!(err.contains("the paper's thin ellipsoid"), "{err}");
}

/// IGI as a user runs it: the JSON reports the VPLs, the gather and the
/// bias compensation; IGI's
/// switches without `--method igi`, the one-shot estimate's accelerations
/// with it, and impossible values are refused with a reason, writing nothing.
#[test]
fn igi_runs_and_refuses_what_it_cannot_do() {
    let d = TempDir::new("igi");
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
    assert_eq!(
        json["igi"]["caustic_paths"], "all",
        "the default caustic map"
    );
    let per_point = json["igi_samples"][0]["vpls_per_point"].as_f64().unwrap();
    assert_eq!(per_point, vpls as f64 / 4.0);
    assert_eq!(
        json["igi"]["bias_compensation"], 16,
        "compensated by default"
    );
    let compensation = &json["bias_compensation_samples"][0];
    assert_eq!(compensation["rays_per_pixel"], 16);
    assert!(
        compensation["queries"].as_u64().unwrap() > 0,
        "{compensation}"
    );
    let refused: [(&[&str], &str); 9] = [
        (&["--interleave", "2"], "--method igi"),
        (&["--bias-compensation", "8"], "--method igi"),
        (
            &["--method", "igi", "--bias-compensation", "1025"],
            "0..=1024",
        ),
        (&["--method", "sppm", "--interleave", "2"], "IGI's switches"),
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

/// Photon differentials as a user runs them: the JSON reports the map (its
/// footprints, s chosen by the pilot, the automatic leaf size) and the
/// estimate; their switches without `--method differentials`, the kNN
/// estimate's accelerations with it, and impossible values are refused with
/// a reason, writing nothing.
#[test]
fn differentials_run_and_refuse_what_they_cannot_do() {
    let d = TempDir::new("differentials");
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
    assert_eq!(map["coverage_samples"], 16, "{map}");
    let sample = &json["footprint_samples"][0];
    assert!(
        sample["mean_footprints"].as_f64().unwrap() > 1.0,
        "{sample}"
    );
    assert!(sample["passes"].as_u64().unwrap() >= 1);
    let refused: [(&[&str], &str); 12] = [
        (&["--leaf-size", "8"], "--method differentials"),
        (&["--footprint-coverage", "4"], "--method differentials"),
        (
            &["--method", "differentials", "--footprint-coverage", "257"],
            "0..=256",
        ),
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
    let d = TempDir::new("radiosity");
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
    // The widest shooter is a quarter (2 x 2 shooters) of a 2 x 2 wall's
    // tile, unsplit or split once (the default --subdivide 1): its diagonal,
    // which `--explain` names.
    let widest = r["largest_shooter"].as_f64().unwrap();
    assert!(
        [2f64.sqrt(), 2f64.sqrt() / 2.0]
            .iter()
            .any(|w| (widest - w).abs() < 1e-4),
        "{widest}"
    );
    let refused: [(&[&str], &str); 17] = [
        (&["--elements", "8"], "--method radiosity"),
        (&["--gather-rays", "4"], "--method radiosity"),
        (
            &["--method", "radiosity", "--gather-rays", "5000"],
            "0..=4096",
        ),
        (
            &["--method", "radiosity", "--final-gather", "4"],
            "--gather-rays N gathers over its solution",
        ),
        (
            &["--caustic-scene-grid"],
            "add --method igi or --method radiosity",
        ),
        (
            &["--method", "sppm", "--caustic-scene-grid"],
            "--caustic-scene-grid",
        ),
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
        (
            &["--caustic-paths", "all"],
            "add --method igi or --method radiosity",
        ),
        (
            &[
                "--method",
                "differentials",
                "--caustic-paths",
                "from-lights",
            ],
            "--method igi",
        ),
        (
            &["--method", "sppm", "--caustic-paths", "all"],
            "--caustic-paths",
        ),
        (
            &["--method", "igi", "--caustic-paths", "some"],
            "from-lights",
        ),
    ];
    for (args, says) in refused {
        assert_render_refused(&d, "cornell_box", args, says);
    }
}

/// `render` of CORNELL BOX at the given size with `args` and `--json` into
/// `dir/out.png`: it succeeds, writes the image, and prints this JSON.
fn render_cornell_box_json(dir: &Path, [w, h]: [&str; 2], args: &[&str]) -> serde_json::Value {
    let png = dir.join("out.png");
    let json = Run::new(["render", "--quiet", "--json", "--width", w, "--height", h])
        .args(args)
        .scene("cornell_box")
        .output_to(&png)
        .json();
    assert!(png.exists());
    json
}

/// `render` of the named scene at 16 x 16 with `args` into `dir/bad.png`
/// fails, says `says`, and writes no image.
fn assert_render_refused(dir: &Path, name: &str, args: &[&str], says: &str) {
    Run::new(["render", "--quiet", "--width", "16", "--height", "16"])
        .args(args)
        .scene(name)
        .output_to(dir.join("bad.png"))
        .refused_with(says);
}

/// `--method vcm` renders with its iterations and its report, each
/// `--vcm-mode` runs, two passes of other seeds merge (`merge --passes`) to
/// their average, and its switches are refused without it, as is what it
/// cannot take.
#[test]
fn vcm_runs_merges_and_refuses_what_it_cannot_do() {
    let d = TempDir::new("vcm");
    for mode in ["pt", "lt", "ppm", "bpt", "vcm"] {
        let v = render_cornell_box_json(
            &d,
            ["24", "24"],
            &["--method", "vcm", "--vcm-mode", mode, "--iterations", "2"],
        );
        assert_eq!(v["method"], "vcm", "{v}");
        assert_eq!(v["vcm_mode"], mode, "{v}");
        assert_eq!(v["iterations"], 2, "{v}");
        assert_eq!(v["provenance"]["method"], "vcm", "{v}");
    }
    // --vcm-techniques writes what each technique carried, which sums to
    // the image.
    let techniques = d.join("techniques");
    let image = d.join("whole.exr");
    Run::new(["render", "--quiet", "--width", "24", "--height", "24"])
        .args(["--method", "vcm", "--iterations", "2"])
        .arg("--vcm-techniques")
        .arg(&techniques)
        .scene("cornell_box")
        .writing("--exr", &image)
        .succeeds();
    let whole = Image::read_exr(&image).unwrap();
    let mut sum = Image::new(whole.width, whole.height);
    for name in [
        "lights_hit",
        "next_event_estimation",
        "connections",
        "merging",
        "light_tracing",
    ] {
        sum.add(&Image::read_exr(&techniques.join(format!("{name}.exr"))).unwrap());
    }
    for (i, (p, q)) in whole.pixels.iter().zip(&sum.pixels).enumerate() {
        for c in 0..3 {
            assert!(
                (p[c] - q[c]).abs() <= 1e-4 * p[c].abs() + 1e-6,
                "pixel {i}: the techniques sum to {} against {}",
                q[c],
                p[c]
            );
        }
    }
    // merge --passes of two seeds is their average (equal iterations).
    let pass = |seed: &str| {
        let exr = d.join(format!("pass{seed}.exr"));
        Run::new(["render", "--quiet", "--width", "24", "--height", "24"])
            .args([
                "--method",
                "vcm",
                "--iterations",
                "2",
                "--light-paths",
                "1024",
            ])
            .args(["--seed", seed])
            .scene("cornell_box")
            .writing("--exr", &exr)
            .succeeds();
        exr
    };
    let (a, b) = (pass("1"), pass("2"));
    let merged = d.join("merged.exr");
    Run::new(["merge", "--passes"])
        .writing_arg(&merged)
        .arg(&a)
        .arg(&b)
        .succeeds();
    let (ia, ib) = (Image::read_exr(&a).unwrap(), Image::read_exr(&b).unwrap());
    let m = Image::read_exr(&merged).unwrap();
    for (i, p) in m.pixels.iter().enumerate() {
        for (c, &v) in p.iter().enumerate() {
            let mean = 0.5 * (ia.pixels[i][c] + ib.pixels[i][c]);
            assert!(
                (v - mean).abs() <= 1e-5 * mean.abs() + 1e-7,
                "pixel {i}: {v} against {mean}"
            );
        }
    }
    for (args, says) in [
        (&["--vcm-mode", "bpt"][..], "add --method vcm"),
        (
            &["--method", "sppm", "--light-paths", "64"][..],
            "add --method vcm",
        ),
        (
            &["--method", "vcm", "--adaptive"][..],
            "no adaptive sampling",
        ),
        (
            &["--method", "vcm", "--spp", "2"][..],
            "--method vcm renders one view",
        ),
        (&["--method", "vcm", "--max-path-length", "1"][..], "2..=64"),
        (&["--method", "vcm", "--merge-alpha", "1"][..], "(0, 1)"),
        (&["--method", "vcm", "--light-paths", "0"][..], "1..="),
        (&["--method", "vcm", "--connections", "17"][..], "1..=16"),
        (
            &["--method", "vcm", "--camera-continuation", "0"][..],
            "(0, 1]",
        ),
        (
            &["--method", "vcm", "--vcm-techniques", "Cargo.toml"][..],
            "not a folder",
        ),
    ] {
        assert_render_refused(&d, "cornell_box", args, says);
    }
}
