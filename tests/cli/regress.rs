//! `photonmap regress` passes RING as it is and catches the defects the
//! reference-image test catches, with a JSON verdict, JUnit XML and images on
//! failure.

use crate::common::{self, Printed, Run, TempDir};

/// regress passes the scene as it is and catches the three defects the
/// regression test catches (a 10% brighter light, the camera one pixel off,
/// the caustic missing), with a JSON verdict, JUnit XML and images on failure.
#[test]
fn regress_catches_a_brighter_light_a_shifted_camera_and_a_missing_caustic() {
    let d = TempDir::new("regress");
    let run = |label: &str, extra: &[&str]| {
        let junit = d.join(format!("{label}.xml"));
        let out = Run::new([
            "regress",
            "scenes/ring.toml",
            "--reference",
            "reference_images",
        ])
        .arg("--json")
        .args(extra)
        .writing("--junit", &junit)
        .writing("--out", d.join(label))
        .in_dir(common::root())
        .umask(0o077)
        .run();
        let v: serde_json::Value = serde_json::from_slice(&out.stdout)
            .unwrap_or_else(|_| panic!("{label}: {}", out.stderr_text()));
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
    // Its JUnit XML and images are 0600, as new files are under umask 077.
    assert!(common::assert_output_modes(&d, 0o077) >= 12);
}
