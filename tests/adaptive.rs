//! Adaptive sampling (section 4.5): the GPU pyramid equals its CPU twin fed
//! with a full render's light, for the one-shot estimate and for final gather,
//! and what it computes is exactly what a full render computes.

mod common;

use glam::Vec3;
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::reference::adaptive::{adaptive_light, FirstHits};
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::{
    render, AdaptiveOptions, EstimateOptions, FinalGatherOptions, GlobalIllumination, Image,
    RenderOptions, RenderOutput,
};
use photonmap::scene::load_scene_str;

fn options(w: u32, h: u32, gather: bool, adaptive: bool, build: BuildMethod) -> RenderOptions {
    let scene = load_scene_str(common::MIRROR_BOX, std::path::Path::new("m.toml")).unwrap();
    let mut o = RenderOptions::for_scene(&scene);
    (o.width, o.height, o.seed) = (w, h, 3);
    o.global = Some(GlobalIllumination {
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
    let scene = load_scene_str(common::MIRROR_BOX, std::path::Path::new("m.toml")).unwrap();
    let (w, h) = (40, 36);
    let full = render(&gpu, &scene, &options(w, h, gather, false, build), &mut ()).unwrap();
    let ad = render(&gpu, &scene, &options(w, h, gather, true, build), &mut ()).unwrap();
    let full_light = global_light(&full);
    let threshold = AdaptiveOptions::default().threshold;
    let (twin, levels) = adaptive_light(&first_hits(&ad), &|i| full_light[i], threshold);
    let got = global_light(&ad);
    let stats = &ad.adaptive[0];
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
