//! `photonmap photons` as a user runs it: the stored count for both builds,
//! the hash grid and its limits, `--faithful`, and projection maps (with
//! `render --explain`, which says whether they ran).

use crate::common::{Run, TempDir};

/// `photonmap photons --json` on a paper scene, which must succeed.
fn photons_json(name: &str, extra: &[&str]) -> serde_json::Value {
    Run::new(["photons", "--json"])
        .args(extra)
        .scene(name)
        .json()
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
        Run::new(["photons"])
            .args(args)
            .scene("ring")
            .refused_with(says);
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
        let d = TempDir::new(&format!("projection-{name}"));
        Run::new(["render", "--quiet", "--explain", "--width", "32"])
            .args(["--height", "24"])
            .output_to(d.join("x.png"))
            .args(extra)
            .scene(name)
            .stderr()
    };
    assert!(explain("ring", &[]).contains("run  projection maps"));
    assert!(explain("ring", &["--no-projection-map"]).contains("skip projection maps"));
    let err = explain("glass_ball", &[]);
    assert!(
        err.contains("skip projection maps") && err.contains("indirect diffuse"),
        "{err}"
    );
}
