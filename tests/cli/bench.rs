//! `photonmap bench ...`: each benchmark's JSON rows and files, and what each
//! refuses before it runs anything (bench mitsuba's budgets, references and
//! masks; `tables --table1-only` without --out).

use crate::common::{self, Run, TempDir};

#[test]
fn bench_build_prints_json_rows() {
    let v = Run::new(["bench", "build", "--json", "--quiet", "--min-log2", "10"])
        .args(["--max-log2", "11"])
        .json();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    assert_eq!(rows[0]["bitonic_passes"], 55);
    assert_eq!(rows[1]["bitonic_passes"], 66);
    assert!(rows[0]["copy_pass_seconds"].as_f64().unwrap() > 0.0);
    Run::new(["bench", "build", "--min-log2", "30"]).refused_with("allowed range");
}

#[test]
fn bench_mask_reports_each_masking() {
    let v = Run::new([
        "bench",
        "mask",
        "--json",
        "--size",
        "64",
        "--iterations",
        "5",
    ])
    .json();
    let rows = v["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 6);
    assert!(rows
        .iter()
        .all(|r| r["wall_seconds"].as_f64().unwrap() > 0.0));
}

#[test]
fn bench_meshes_reports_every_size_with_rates_renders_and_a_plot() {
    let d = TempDir::new("meshes");
    let report = Run::new(["bench", "meshes", "--triangles", "8,2000", "--width", "48"])
        .args(["--height", "32", "--photons", "4096", "--json"])
        .writing("--out", &d)
        .umask(0o077)
        .json();
    // Its JSON, SVG and renders are 0600, as new files are under umask 077.
    assert!(common::assert_output_modes(&d, 0o077) >= 4);
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
    Run::new(["bench", "meshes", "--triangles", "4"]).refused_with("8");
}

/// `bench igi` on the mesh stage: the paper's four versions and two remedies,
/// each with its time split into components that add up to it (the stages
/// outside them are few and small), its image, and no reference to compare.
#[test]
fn bench_igi_splits_each_version_by_component() {
    let d = TempDir::new("bench-igi");
    let v = Run::new(["bench", "igi", "--triangles", "1024", "--vpl-paths", "16"])
        .args(["--json", "--quiet"])
        .writing("--out", &d)
        .json();
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
    assert_eq!(
        rows[0]["options"]["interleave"], 1,
        "canonical IGI: no subsets"
    );
    assert!(rows[3]["options"]["interleave"] == 3 && rows[3]["options"]["downsample"] == 4);
    assert!(d.join("igi.json").is_file() && d.join("00_igi.png").is_file());
}

/// `bench differentials --quick` on RING: both methods, the leaf sizes with
/// the automatic one last, and the footprint scales each beside the
/// kNN-grid at the k_PD they reached; errors against the SPPM reference.
#[test]
fn bench_differentials_compares_methods_leaf_sizes_and_k() {
    let d = TempDir::new("bench-differentials");
    let v = Run::new(["bench", "differentials", "--scene", "ring", "--quick"])
        .args(["--json", "--quiet"])
        .writing("--out", &d)
        .json();
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

/// `bench mitsuba` runs Mitsuba through --python, and says before any render
/// when it cannot; `tables --table1-only` needs --out (it would replace the
/// full run's tables.md).
#[test]
fn bench_mitsuba_and_tables_refuse_what_they_cannot_do() {
    Run::new(["bench", "mitsuba", "--scene", "glass_ball"])
        .args(["--python", "/nonexistent/python3"])
        .refused_with("/nonexistent/python3");
    Run::new(["tables", "--table1-only", "--quiet"]).refused_with("--table1-only needs --out");
}

/// `bench mitsuba` refuses a budget that is not a positive number of
/// seconds, a --reference or --mask that is not there, a mask of another
/// size, a --mitsuba-reference that cannot be made, and a --region that is
/// malformed, outside the reference or all masked, before it runs Mitsuba
/// or writes anything.
#[test]
fn bench_mitsuba_refuses_bad_budgets_references_and_masks() {
    let d = TempDir::new("bench-mitsuba");
    let out_dir = d.join("out");
    let refused: [(&[&str], &str); 13] = [
        (&["--region", "floor=0:10:5"], "NAME=X0:X1:Y0:Y1"),
        (
            &["--region", "floor=0:257:0:10"],
            "outside the 256 x 192 pixels of the reference",
        ),
        // The truth's mask of GLASS BALL leaves out its top-left corner (the black sky).
        (&["--region", "corner=0:1:0:1"], "the mask leaves none"),
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
        Run::new(["bench", "mitsuba", "--scene", "glass_ball", "--quiet"])
            .args(["--python", "/nonexistent/python3"])
            .writing("--out", &out_dir)
            .args(args)
            .in_dir(common::root())
            .refused_with(says);
        assert!(!out_dir.exists(), "{args:?} wrote {}", out_dir.display());
    }
}

/// `bench throughput` without Mitsuba: each SPPM stage with its records and
/// copy-pass floor, and the direct-light render's rate; it refuses bad
/// iteration counts and a Python without Mitsuba before it runs anything.
#[test]
fn bench_throughput_reports_each_stage_against_its_floor() {
    let d = TempDir::new("throughput");
    let v = Run::new([
        "bench",
        "throughput",
        "--no-mitsuba",
        "--scene",
        "glass_ball",
    ])
    .args([
        "--width",
        "32",
        "--height",
        "24",
        "--spp",
        "2",
        "--shadow-rays",
        "2",
    ])
    .args([
        "--iterations",
        "1",
        "3",
        "--repeats",
        "1",
        "--json",
        "--quiet",
    ])
    .writing("--out", &d)
    .json();
    let scene = &v["scenes"][0];
    assert_eq!(scene["scene"], "glass_ball");
    assert_eq!(scene["diffuse"], false);
    let stages = scene["stages"].as_array().unwrap();
    let stage = |name: &str| {
        stages
            .iter()
            .find(|s| s["stage"].as_str().unwrap().starts_with(name))
            .unwrap_or_else(|| panic!("no stage {name}: {stages:?}"))
    };
    let photons = v["sppm_photons_per_iteration"].as_u64().unwrap();
    assert_eq!(stage("eye paths")["records"], 32 * 24);
    assert_eq!(stage("trace photons")["records"], photons);
    assert_eq!(stage("gather + update")["records"], 32 * 24);
    for s in stages {
        let (seconds, records) = (
            s["seconds"].as_f64().unwrap(),
            s["records"].as_f64().unwrap(),
        );
        let copy = s["copy_seconds"].as_f64().unwrap();
        assert!(copy > 0.0, "{s}");
        assert!((s["per_second"].as_f64().unwrap() * seconds - records).abs() <= 1e-6 * records);
        assert!(
            (s["copy_passes"].as_f64().unwrap() * copy - seconds).abs()
                <= 1e-9 + 1e-6 * seconds.abs()
        );
    }
    let direct = &scene["direct"];
    let seconds = direct["seconds"].as_f64().unwrap();
    assert!(seconds > 0.0);
    let rate = direct["eye_paths_per_second"].as_f64().unwrap();
    assert!((rate * seconds - (32 * 24 * 2) as f64).abs() < 1e-6 * rate * seconds);
    assert!(direct["mitsuba_seconds"].is_null() && scene["mitsuba"].is_null());
    assert!(d.join("throughput.json").is_file());

    Run::new([
        "bench",
        "throughput",
        "--no-mitsuba",
        "--iterations",
        "4",
        "4",
    ])
    .refused_with("SHORT < LONG");
    Run::new(["bench", "throughput", "--python", "/nonexistent/python3"])
        .refused_with("/nonexistent/python3");
}
