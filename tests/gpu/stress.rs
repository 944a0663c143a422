//! The quick stress cases on the real pipeline: none may fail, the impossible
//! ones are refused with a clear message, and the furnace holds its analytic value.

use crate::common;

use photonmap::bench::stress::{run, Outcome};

#[test]
fn quick_stress_cases_pass_or_refuse_clearly() {
    let gpu = common::gpu();
    let cases = run(&gpu, true, &|_| {});
    for c in &cases {
        eprintln!("{:?} {} = {} ({})", c.outcome, c.name, c.value, c.message);
    }
    let failed: Vec<_> = cases
        .iter()
        .filter(|c| c.outcome == Outcome::Fail)
        .map(|c| format!("{}: {}", c.name, c.message))
        .collect();
    assert!(failed.is_empty(), "failed: {failed:#?}");
    let refused = |name: &str, says: &str| {
        let c = cases
            .iter()
            .find(|c| c.name.starts_with(name))
            .unwrap_or_else(|| panic!("no case {name}"));
        assert_eq!(c.outcome, Outcome::Refused, "{name}");
        assert!(c.message.contains(says), "{name}: {}", c.message);
    };
    refused("--faithful float addressing past 2^24", "2^24");
    refused("maximum radius zero", "photon_map.max_radius");
    refused("zero-area light", "no area");
    refused("NaN in a position", "not a finite number");
    refused("an empty photon map", "none stored");
    assert!(cases
        .iter()
        .any(|c| c.name.starts_with("furnace") && c.outcome == Outcome::Pass));
    assert!(cases.len() >= 15, "{} cases", cases.len());
}

#[test]
fn the_furnace_holds_its_analytic_radiance() {
    let gpu = common::gpu();
    let (mean, expected, tolerance, bad) = photonmap::bench::stress::furnace(&gpu).unwrap();
    assert!(bad.is_empty(), "non-finite values: {bad}");
    eprintln!("furnace: {mean:.5} against {expected:.5} +- {tolerance:.5}");
    assert!(
        (mean - expected).abs() <= tolerance,
        "{mean} vs {expected} +- {tolerance}"
    );
    // Without the photon map only the direct part, rho I / (pi R^2), remains:
    // half the total here, which the tolerance must tell apart.
    assert!(expected * 0.5 < expected - tolerance);
}
