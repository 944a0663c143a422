//! Radiosity's caustic deposit (`--shoot-caustics`) against the caustic map
//! it comes from: every caustic photon's reflected power enters the
//! elements, as radiosity, as unshot residual, as the direct part that
//! the image leaves to the caustic map, and as the deposit that a gather
//! hit keeps, which splits and shots leave as it was.

use photonmap::photon::PhotonMap;
use photonmap::render::photon_options::CAUSTIC_K;
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
    let scene = mirror_ball_box("");
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
    assert_eq!(
        deposit_sum(&without),
        0.0,
        "nothing deposited when not shot"
    );
    let (direct_on, b_on, residual_on) = box_sums(&with);
    let (direct_off, b_off, residual_off) = box_sums(&without);
    let reflected = reflected_caustic_power(&with);
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
        deposit_sum(&with),
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

/// The same box solved to convergence with adaptive subdivision: tiles
/// split after the deposit, and their children must inherit it, while the
/// shots add none to it.
#[test]
fn splits_and_shots_keep_the_caustic_deposit() {
    let out = solve(&mirror_ball_box(""), RadiosityOptions::default());
    let report = &out.radiosity_run().unwrap().report;
    let (reflected, deposit) = (reflected_caustic_power(&out), deposit_sum(&out));
    println!(
        "{} splits, {} shots: deposit {deposit:.6}, reflected caustic power {reflected:.6}",
        report.splits, report.shots
    );
    assert!(report.splits > 0 && report.shots > 1);
    assert!(
        (deposit - reflected).abs() <= 1e-3 * reflected,
        "deposit {deposit}, reflected {reflected}"
    );
}

/// The caustic map's records (position w = 1), power scaled to the photons
/// in use, reflected at the box's albedo 0.5 (red channel).
fn reflected_caustic_power(out: &photonmap::render::RenderOutput) -> f64 {
    let caustics = out.radiosity_run().unwrap().caustics.as_ref().unwrap();
    let PhotonMap::Sorted(map) = &caustics.map else {
        panic!("the default build sorts");
    };
    let (position, power) = (common::texels(&map.position), common::texels(&map.power));
    position
        .iter()
        .zip(&power)
        .filter(|(p, _)| p[3] == 1.0)
        .map(|(_, w)| 0.5 * f64::from(w[0]))
        .sum()
}

/// The deposit texture's power over the live elements of diffuse patches
/// (red channel).
fn deposit_sum(out: &photonmap::render::RenderOutput) -> f64 {
    let r = &out.radiosity_run().unwrap().radiosity;
    let e = &r.elements;
    let deposit = common::texels(&r.deposit);
    e.position
        .iter()
        .enumerate()
        .filter(|(t, pos)| pos[3] > 0.0 && !e.patches[e.normal[*t][3] as usize].emitter)
        .map(|(t, pos)| f64::from(deposit[t][0]) * f64::from(pos[3]))
        .sum()
}

/// The closed box of albedo 0.5 (scenes/tests/closed_box.toml) lit by a
/// 0.4 x 0.4 area light under its ceiling, with a mirror ball under the
/// light; `photon_map` holds the lines of its photon-map section.
fn mirror_ball_box(photon_map: &str) -> photonmap::scene::Scene {
    let ball = r#"
[[shape]]
type = "sphere"
center = [0.0, -0.4, 0.0]
radius = 0.4
material = "mirror"
"#;
    let text = common::fixture_text("closed_box");
    let (walls, _point_light) = text.split_once("[[light]]").unwrap();
    let text = common::replace_once(
        &format!("{walls}{}{ball}", crate::radiosity::CEILING_LIGHT),
        "wall = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }",
        "wall = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }\nmirror = { type = \"mirror\", reflectance = [1.0, 1.0, 1.0] }",
    );
    let text = format!("{text}\n[photon_map]\n{photon_map}\n");
    photonmap::scene::load_scene_str(&text, std::path::Path::new("r.toml")).unwrap()
}

#[test]
fn the_caustic_map_reads_its_own_k_by_default_at_most_caustic_k() {
    // A scene k above CAUSTIC_K: by default the caustic map's estimate reads
    // CAUSTIC_K photons, and given one it reads that many.
    let scene = mirror_ball_box("k = 200");
    assert_eq!(scene.photon_map.k, 200);
    let image = |caustic_k| {
        solve(
            &scene,
            RadiosityOptions {
                max_shots: 1,
                subdivide: 0,
                caustic_k,
                ..RadiosityOptions::default()
            },
        )
        .image
    };
    let by_default = image(None);
    assert_eq!(
        common::channels_differing(&by_default, &image(Some(CAUSTIC_K))),
        0
    );
    assert!(common::channels_differing(&by_default, &image(Some(200))) > 0);
}
