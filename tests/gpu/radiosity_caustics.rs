//! Radiosity's caustic deposit (`--shoot-caustics`) against the caustic map
//! it comes from: every caustic photon's reflected power enters the
//! elements, as radiosity, as unshot residual and as the direct part that
//! the image leaves to the caustic map.

use photonmap::photon::PhotonMap;
use photonmap::render::RadiosityOptions;

use super::radiosity::{box_sums, solve};
use crate::common;

#[test]
fn the_caustic_deposit_adds_the_reflected_power_of_every_caustic_photon() {
    // The closed box of albedo 0.5 with a mirror ball under a light: the
    // caustic map holds the light the ball reflects onto the walls. One
    // shot (the light's, the tile of most power, the same with and
    // without the deposit) and no subdivision, so what the deposit adds is
    // the difference of the two solutions.
    let light = r#"
[[light]]
type = "area"
corner = [-0.2, 0.98, -0.2]
edge1 = [0.4, 0.0, 0.0]
edge2 = [0.0, 0.0, 0.4]
normal = [0.0, -1.0, 0.0]
radiance = [1.0, 1.0, 1.0]

[[shape]]
type = "sphere"
center = [0.0, -0.4, 0.0]
radius = 0.4
material = "mirror"
"#;
    let text = common::fixture_text("closed_box");
    let (walls, _point_light) = text.split_once("[[light]]").unwrap();
    let text = common::replace_once(
        &format!("{walls}{light}"),
        "wall = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }",
        "wall = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }\nmirror = { type = \"mirror\", reflectance = [1.0, 1.0, 1.0] }",
    );
    let scene = photonmap::scene::load_scene_str(&text, std::path::Path::new("r.toml")).unwrap();
    let run = |shoot_caustics| {
        solve(
            &scene,
            RadiosityOptions {
                max_shots: 1,
                subdivide: 0,
                shoot_caustics,
                ..RadiosityOptions::default()
            },
        )
    };
    let (with, without) = (run(true), run(false));
    let (direct_on, b_on, residual_on) = box_sums(&with);
    let (direct_off, b_off, residual_off) = box_sums(&without);
    // The caustic map's records (position w = 1), power scaled to the
    // photons in use, reflected at albedo 0.5.
    let caustics = with.radiosity_run().unwrap().caustics.as_ref().unwrap();
    let PhotonMap::Sorted(map) = &caustics.map else {
        panic!("the default build sorts");
    };
    let (position, power) = (common::texels(&map.position), common::texels(&map.power));
    let reflected: f64 = position
        .iter()
        .zip(&power)
        .filter(|(p, _)| p[3] == 1.0)
        .map(|(_, w)| 0.5 * f64::from(w[0]))
        .sum();
    let report = with.radiosity_run().unwrap().report.caustic_shot_fraction;
    println!(
        "reflected caustic power {reflected:.6}; deposited: radiosity {:.6}, direct {:.6}, residual {:.6}; reported {report:?}",
        b_on - b_off,
        direct_on - direct_off,
        residual_on - residual_off
    );
    assert!(reflected > 0.01, "the ball sends caustics onto the walls");
    for deposited in [
        b_on - b_off,
        direct_on - direct_off,
        residual_on - residual_off,
    ] {
        assert!(
            (deposited - reflected).abs() <= 1e-3 * reflected,
            "deposited {deposited}, reflected {reflected}"
        );
    }
    assert!(
        report.is_some()
            && without
                .radiosity_run()
                .unwrap()
                .report
                .caustic_shot_fraction
                .is_none()
    );
}
