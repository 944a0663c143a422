//! Photon differentials' caustic footprint map (`--caustic-photons`): the
//! scene's own caustic footprints are left out, its others are untouched,
//! and the caustic map's photons, aimed by projection maps, carry the same
//! caustic power the left-out ones did, within their noise.

use photonmap::photon::differentials::FootprintMap;
use photonmap::render::{
    render, DifferentialsOptions, DifferentialsRun, Method, RenderOptions, RenderOutput,
    WithPhotons,
};
use photonmap::scene::Scene;

use crate::common;

fn run(scene: &Scene, caustic_photons: Option<u32>) -> RenderOutput {
    let mut options = RenderOptions::for_scene(scene);
    (options.width, options.height, options.seed) = (16, 16, 7);
    options.method = Method::Differentials(WithPhotons {
        method: DifferentialsOptions {
            smoothing: Some(2.0),
            caustic_photons,
            ..DifferentialsOptions::default()
        },
        ..WithPhotons::default()
    });
    render(&common::gpu(), scene, &options, &mut ()).unwrap()
}

fn state(out: &RenderOutput) -> &DifferentialsRun {
    out.differentials_run().unwrap()
}

/// Each footprint as (area, diffuse, power summed over rgb, left out).
fn footprints(m: &FootprintMap) -> Vec<(f32, bool, f64, bool)> {
    let [f0, f1, _, f3] = m.footprints.each_ref().map(common::texels);
    (0..m.count as usize)
        .map(|i| {
            let power = f3[i][..3].iter().map(|&c| f64::from(c)).sum();
            (f0[i][3], f1[i][3] != 0.0, power, f3[i][3] != 0.0)
        })
        .collect()
}

#[test]
fn the_caustic_map_replaces_the_scene_s_caustic_footprints_with_their_power() {
    let scene = common::fixture("mirror_box");
    let (one, two) = (run(&scene, Some(0)), run(&scene, None));
    let (one, two) = (state(&one), state(&two));
    assert!(one.caustic.is_none(), "0: the paper's one map");
    let single = footprints(one.map.as_ref().unwrap());
    let main = footprints(two.map.as_ref().unwrap());
    // The same photons (the scene's, on the same seed) in the same order.
    assert_eq!(single.len(), main.len());
    let (mut dropped, mut caustic_power, mut caustics) = (0u32, 0f64, 0u32);
    for (s, m) in single.iter().zip(&main) {
        assert_eq!(s.1, m.1, "the same photon, diffuse or not");
        if s.1 {
            assert_eq!(
                (s.0, s.2, s.3),
                (m.0, m.2, m.3),
                "a diffuse footprint is untouched"
            );
        } else {
            assert!(m.3 && m.0 == 0.0 && m.2 == 0.0, "a caustic one is left out");
            dropped += 1;
            if s.0 > 0.0 {
                caustics += 1;
                caustic_power += s.2;
            }
        }
    }
    let map = two.map.as_ref().unwrap();
    assert_eq!(map.dropped_caustics, dropped);
    assert!(caustics > 200, "{caustics} caustic footprints to compare");

    // The caustic map: as many photons as the scene stores, every one
    // caustic, with the power the scene's caustic photons carried.
    let c = two
        .caustic
        .as_ref()
        .expect("auto: the scene has a mirror and glass");
    let cmap = c.map.as_ref().unwrap();
    assert_eq!(cmap.count, scene.photon_map.photons_stored);
    assert_eq!(cmap.diffuse, 0);
    let aimed = footprints(cmap);
    let aimed_power: f64 = aimed.iter().filter(|f| f.0 > 0.0).map(|f| f.2).sum();
    // Each side's relative noise is about 1 / sqrt(its photons).
    let sigma = (1.0 / f64::from(caustics) + 1.0 / aimed.len() as f64).sqrt();
    let ratio = aimed_power / caustic_power;
    println!("caustic power: aimed {aimed_power:.5}, the scene's {caustic_power:.5}, ratio {ratio:.4} (sigma {sigma:.4})");
    assert!(
        (ratio - 1.0).abs() < 4.0 * sigma,
        "ratio {ratio}, sigma {sigma}"
    );
}
