//! Adaptive sampling (section 4.5): the GPU pyramid equals its CPU twin fed
//! with a full render's light, for the one-shot estimate and for final gather,
//! and what it computes is exactly what a full render computes.

use crate::common;

use glam::Vec3;
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::{
    render, AdaptiveOptions, EstimateOptions, FinalGatherOptions, Image, Method, PhotonMapOptions,
    RenderOptions, RenderOutput,
};
use photonmap::twins::adaptive::{adaptive_light, FirstHits};

fn options(w: u32, h: u32, gather: bool, adaptive: bool, build: BuildMethod) -> RenderOptions {
    let scene = common::fixture("mirror_box");
    let mut o = RenderOptions::for_scene(&scene);
    (o.width, o.height, o.seed) = (w, h, 3);
    o.method = Method::PhotonMap(PhotonMapOptions {
        photons: PhotonConfig {
            build,
            ..PhotonConfig::default()
        },
        estimate: EstimateOptions {
            leak: LeakTest::None,
            ..EstimateOptions::default()
        },
        final_gather: gather.then(|| FinalGatherOptions {
            rays: 4,
            ..FinalGatherOptions::default()
        }),
        adaptive: adaptive.then(AdaptiveOptions::default),
    });
    o
}

/// A render's global light (its image less its direct light), in GL order.
fn global_light(out: &RenderOutput) -> Vec<Vec3> {
    let direct: Image = out.state.direct.read_radiance();
    let (w, h) = (out.image.width as usize, out.image.height as usize);
    (0..w * h)
        .map(|gl| {
            let (x, y) = (gl % w, gl / w);
            let i = (h - 1 - y) * w + x;
            let (a, d) = (out.image.pixels[i], direct.pixels[i]);
            Vec3::new(a[0] - d[0], a[1] - d[1], a[2] - d[2])
        })
        .collect()
}

fn first_hits(out: &RenderOutput) -> FirstHits {
    let normals = out.state.direct.diffuse_normal.read_f32();
    FirstHits {
        width: out.image.width,
        height: out.image.height,
        normal: normals
            .chunks(4)
            .map(|c| Vec3::new(c[0], c[1], c[2]))
            .collect(),
        material: normals.chunks(4).map(|c| c[3]).collect(),
    }
}

/// Renders the box in full and adaptively on the same photons and eye paths;
/// the twin, given the full render's light at the pixels it computes, must
/// plan the same levels and give the adaptive image. Plans may differ only
/// where a corner contrast sits on the threshold to rounding.
fn check(gather: bool, build: BuildMethod) {
    let gpu = common::gpu();
    let scene = common::fixture("mirror_box");
    let (w, h) = (40, 36);
    let full = render(&gpu, &scene, &options(w, h, gather, false, build), &mut ()).unwrap();
    let ad = render(&gpu, &scene, &options(w, h, gather, true, build), &mut ()).unwrap();
    let full_light = global_light(&full);
    let threshold = AdaptiveOptions::default().threshold;
    let (twin, levels) = adaptive_light(&first_hits(&ad), &|i| full_light[i], threshold);
    let got = global_light(&ad);
    let stats = &ad.adaptive()[0];
    let apart = got
        .iter()
        .zip(&twin)
        .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-4 + 1e-3 * b.max_element())
        .count();
    let saved = 1.0 - stats.computed as f64 / stats.pixels_with_hits as f64;
    eprintln!(
        "adaptive (final gather {gather}, {build:?}): GPU levels {:?}, twin {levels:?}; {apart} of {} pixels apart; {:.0}% of pixels interpolated",
        stats.levels,
        got.len(),
        100.0 * saved
    );
    for ((s, c, i), (ts, tc, ti)) in stats.levels.iter().zip(&levels) {
        assert_eq!(s, ts);
        assert!(
            c.abs_diff(*tc) <= 2 && i.abs_diff(*ti) <= 2,
            "{c} {i} vs {tc} {ti}"
        );
    }
    assert!(apart * 100 <= got.len(), "{apart} pixels apart");
    assert!(saved > 0.2, "the box's smooth walls are interpolated");
}

#[test]
fn adaptive_estimate_equals_its_cpu_twin() {
    check(false, BuildMethod::Bitonic);
}

#[test]
fn adaptive_final_gather_equals_its_cpu_twin() {
    check(true, BuildMethod::Bitonic);
}

#[test]
fn adaptive_final_gather_on_stencil_routing_equals_its_cpu_twin() {
    check(true, BuildMethod::Stencil);
}

/// Adaptive SPPM against full SPPM on the same seeds, and against the twin.
/// The pilot is full SPPM; the plan made on its photon half is the twin's
/// pyramid; afterwards every computed pixel follows the full run's state
/// (its photon count exactly, flux and radius to float precision: the grid's
/// cells, sized by the largest radius among the pixels that still gather,
/// change only the order of the sums), and the image's photon half is the
/// twin's fill of those pixels on the GPU's plan.
#[test]
fn adaptive_sppm_computes_what_full_sppm_does_and_fills_as_its_twin() {
    use photonmap::render::sppm::{Sppm, SppmOptions};
    use photonmap::timing::Timings;
    use photonmap::twins::adaptive::{adaptive_pyramid, fill_planned};
    let gpu = common::gpu();
    let scene = common::fixture("mirror_box");
    let (w, h, pilot, iterations) = (48u32, 40u32, 2u32, 6u32);
    let o = options(w, h, false, false, BuildMethod::Bitonic);
    let sppm = |adaptive: bool| SppmOptions {
        iterations,
        adaptive: adaptive.then(AdaptiveOptions::default),
        adaptive_pilot: Some(pilot),
        ..SppmOptions::default()
    };
    let mut full = Sppm::new(&gpu, &scene, &o, &sppm(false)).unwrap();
    let mut ad = Sppm::new(&gpu, &scene, &o, &sppm(true)).unwrap();
    let mut timings = Timings::default();
    for _ in 0..pilot {
        full.iterate(&mut timings, &mut ()).unwrap();
        ad.iterate(&mut timings, &mut ()).unwrap();
    }
    // The pilot's photon half and first hits, which the next iteration plans on.
    let pilot_light: Vec<Vec3> = gl_order(&ad.image_parts(false, true).unwrap());
    let normals = common::texels(&ad.direct.diffuse_normal);
    let first = FirstHits {
        width: w,
        height: h,
        normal: normals.iter().map(|&n| common::v3(n)).collect(),
        material: normals.iter().map(|n| n[3]).collect(),
    };
    let pilot_count: Vec<f32> = common::texels(&full.state.sums)
        .iter()
        .map(|s| s[3])
        .collect();
    let threshold = AdaptiveOptions::default().threshold;
    let twin = adaptive_pyramid(&first, &|i| pilot_light[i], threshold);
    for _ in pilot..iterations {
        full.iterate(&mut timings, &mut ()).unwrap();
        ad.iterate(&mut timings, &mut ()).unwrap();
    }
    let a = ad.adaptive.as_ref().unwrap();
    let planned = a.planned.as_ref().expect("planned after the pilot");
    // The plan: the twin's, but where a corner contrast sits on the threshold.
    let plan_apart = planned
        .fill_levels
        .iter()
        .zip(&twin.interpolated_at)
        .filter(|(g, t)| g != t)
        .count();
    // Computed pixels: the full run's state.
    let (packed_flux, packed_sums) = (
        common::texels(&planned.state.flux),
        common::texels(&planned.state.sums),
    );
    let (full_flux, full_sums) = (
        common::texels(&full.state.flux),
        common::texels(&full.state.sums),
    );
    let rel = |a: f32, b: f32| (a - b).abs() / (a.abs().max(b.abs()) + 1e-6);
    let (mut compared, mut lazy, mut counts_apart, mut worst) = (0, 0, 0, 0f32);
    for (slot, &p) in planned.computed.iter().enumerate() {
        let p = p as usize;
        // A pixel that had gathered nothing in the pilot takes its first
        // radius from the grid's cell, which differs between the runs.
        if pilot_count[p] == 0.0 {
            lazy += 1;
            continue;
        }
        compared += 1;
        if packed_sums[slot][3] != full_sums[p][3] {
            counts_apart += 1;
            continue;
        }
        for c in 0..4 {
            worst = worst.max(rel(packed_flux[slot][c], full_flux[p][c]));
        }
    }
    // Direct light accumulates at every pixel, as in the full run.
    let ad_sums = common::texels(&ad.state.sums);
    let direct_apart = (0..ad_sums.len())
        .filter(|&i| (0..3).any(|c| ad_sums[i][c] != full_sums[i][c]))
        .count();
    // The image's photon half: the twin's fill of the GPU's computed pixels.
    let mut computed_light = vec![Vec3::ZERO; (w * h) as usize];
    for (slot, &p) in planned.computed.iter().enumerate() {
        let (f, s) = (packed_flux[slot], packed_sums[slot]);
        if s[3] > 0.0 && f[3] > 0.0 {
            computed_light[p as usize] =
                common::v3(f) / (std::f32::consts::PI * f[3] * iterations as f32);
        }
    }
    let filled = fill_planned(w, h, &planned.fill_levels, &|i| computed_light[i]);
    let got = gl_order(&ad.image_parts(false, true).unwrap());
    let fill_apart = got
        .iter()
        .zip(&filled)
        .filter(|(a, b)| (**a - **b).abs().max_element() > 1e-6 + 1e-5 * b.max_element())
        .count();
    let interpolated = planned.fill_levels.iter().filter(|&&l| l >= 0).count();
    eprintln!(
        "adaptive SPPM: {interpolated} of {} pixels interpolated (GPU levels {:?}, twin {:?}); plan apart at {plan_apart}; {compared} computed pixels compared with the full run ({lazy} had gathered nothing in the pilot): counts apart at {counts_apart}, largest relative difference {worst:.2e}; direct light apart at {direct_apart}; fill apart at {fill_apart}",
        w * h,
        planned.stats.levels,
        twin.levels
    );
    assert!(
        interpolated * 5 > (w * h) as usize,
        "the box's walls are interpolated"
    );
    assert!(
        plan_apart * 200 <= (w * h) as usize,
        "{plan_apart} plans apart"
    );
    assert!(
        lazy * 20 <= compared,
        "{lazy} pixels without photons after the pilot"
    );
    assert_eq!(counts_apart, 0);
    assert!(worst < 1e-4, "{worst}");
    assert_eq!(direct_apart, 0);
    assert_eq!(fill_apart, 0);
}

/// An image's pixels in GL order (row 0 at the bottom), as the lattices are.
fn gl_order(image: &Image) -> Vec<Vec3> {
    let (w, h) = (image.width as usize, image.height as usize);
    (0..w * h)
        .map(|gl| {
            let p = image.pixels[(h - 1 - gl / w) * w + gl % w];
            Vec3::new(p[0], p[1], p[2])
        })
        .collect()
}
