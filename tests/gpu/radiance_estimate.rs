//! The kNN-grid radiance estimate on the GPU against its CPU twin, against
//! brute force, across drawing modes, and against an analytic irradiance.

use crate::common;

use glam::Vec3;
use photonmap::photon::{BuildMethod, Grid, PhotonConfig, PhotonFrames, PhotonMap};
use photonmap::render::{
    render, EstimateMode, Method, PhotonMapOptions, RenderOptions, RenderOutput,
};
use photonmap::scene::Scene;
use photonmap::twins::knn::{knn_grid, CpuPhotonMap, KnnResult};

/// The paper's three scenes, each at the small size its tests render.
const PAPER_SCENES: [(&str, u32, u32); 3] = [
    ("glass_ball", 64, 48),
    ("cornell_box", 48, 48),
    ("ring", 64, 48),
];

fn render_gi(
    scene: &Scene,
    width: u32,
    height: u32,
    build: BuildMethod,
    mode: EstimateMode,
) -> RenderOutput {
    let gpu = common::gpu();
    let o = gi_options(scene, width, height, build, mode);
    render(&gpu, scene, &o, &mut ()).unwrap()
}

/// The paper's estimate (no leak test) with `build`, at width x height.
fn gi_options(
    scene: &Scene,
    width: u32,
    height: u32,
    build: BuildMethod,
    mode: EstimateMode,
) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (width, height, 3);
    let mut gi = PhotonMapOptions {
        photons: PhotonConfig {
            build,
            ..PhotonConfig::default()
        },
        ..PhotonMapOptions::default()
    };
    gi.estimate.mode = mode;
    gi.estimate.budget = 48;
    // The paper's estimate, which the CPU twin, brute force and the software
    // reference compute (the leak tests have their own test below).
    gi.estimate.leak = photonmap::render::radiance_estimate::LeakTest::None;
    o.method = Method::PhotonMap(gi);
    o
}

/// Per query pixel: (position, GPU flux, GPU r^2, GPU accepted).
fn gpu_results(out: &RenderOutput) -> Vec<(usize, Vec3, Vec3, f32, u32)> {
    let est = out.radiance_estimate().unwrap();
    let flux = est.flux.read_f32();
    let cursor = est.cursor.read_i32();
    let done = est.done.read_i32();
    let pos = out.state.direct.diffuse_position.read_f32();
    let mut v = Vec::new();
    for i in 0..pos.len() / 4 {
        if pos[4 * i + 3] > 0.0 {
            assert_eq!(done[4 * i], 1, "pixel {i} never finished");
            v.push((
                i,
                Vec3::from_slice(&pos[4 * i..]),
                Vec3::from_slice(&flux[4 * i..]),
                flux[4 * i + 3],
                cursor[4 * i] as u32,
            ));
        }
    }
    v
}

/// At most one in `per` of the GPU's queries `results` end otherwise than
/// `twin(pixel, position)`'s: another accepted count, or radius or flux beyond
/// float precision. The first few, and the count, are printed, named `what`.
fn assert_agrees_with_twin(
    what: &str,
    results: &[(usize, Vec3, Vec3, f32, u32)],
    per: usize,
    twin: impl Fn(usize, Vec3) -> KnnResult,
) {
    let mut mismatched = 0;
    for &(i, x, flux, r2, accepted) in results {
        let cpu = twin(i, x);
        let same = cpu.accepted == accepted
            && (cpu.radius2 - r2).abs() <= 1e-5 * r2.max(1e-12)
            && (cpu.flux - flux).abs().max_element() <= 1e-4 * cpu.flux.max_element().max(1e-20);
        if !same {
            mismatched += 1;
            if mismatched < 4 {
                eprintln!(
                    "{what} pixel {i}: GPU {accepted} {r2} {flux}, CPU {} {} {}",
                    cpu.accepted, cpu.radius2, cpu.flux
                );
            }
        }
    }
    eprintln!(
        "{what}: {} query pixels, {mismatched} differ from the CPU twin",
        results.len()
    );
    assert!(
        mismatched * per <= results.len(),
        "{what}: {mismatched} pixels differ"
    );
}

#[test]
fn gpu_knn_grid_equals_the_cpu_knn_grid_for_both_builds() {
    for (name, w, h) in PAPER_SCENES {
        let scene = common::paper_scene(name);
        for build in [BuildMethod::Bitonic, BuildMethod::Stencil] {
            let out = render_gi(&scene, w, h, build, EstimateMode::Tiled { tile: 16 });
            let cpu_map = CpuPhotonMap::from_gpu(out.map().unwrap());
            let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
            let results = gpu_results(&out);
            assert!(
                results.len() > (w * h / 3) as usize,
                "{name}: only {} query pixels",
                results.len()
            );
            // A photon exactly at the radius can fall either side of f32 rounding.
            assert_agrees_with_twin(&format!("{name} {build:?}"), &results, 1000, |_, x| {
                knn_grid(&cpu_map, x, k, max_r)
            });
        }
    }
}

#[test]
fn the_knn_grid_holds_the_true_k_nearest() {
    let scene = common::paper_scene("cornell_box");
    let out = render_gi(
        &scene,
        32,
        32,
        BuildMethod::Bitonic,
        EstimateMode::FullScreen,
    );
    let cpu_map = CpuPhotonMap::from_gpu(out.map().unwrap());
    let photons: Vec<(Vec3, Vec3)> = cpu_map.photons().copied().collect();
    let (k, max_r) = (scene.photon_map.k as usize, scene.photon_map.max_radius);
    let mut checked = 0;
    let results = gpu_results(&out);
    assert!(results.len() > 800, "{} query pixels", results.len());
    for (i, x, _flux, r2, accepted) in results {
        let mut d2: Vec<f32> = photons
            .iter()
            .map(|(p, _)| (*p - x).length_squared())
            .filter(|d| *d <= max_r * max_r)
            .collect();
        d2.sort_by(f32::total_cmp);
        if d2.len() >= k {
            // At least k found, the radius reaches the true k-th nearest ...
            assert!(
                accepted as usize >= k,
                "pixel {i}: {accepted} accepted of {} in range",
                d2.len()
            );
            assert!(
                r2 >= d2[k - 1],
                "pixel {i}: radius^2 {r2} < k-th nearest {}",
                d2[k - 1]
            );
            // ... and every photon inside the radius is in the estimate (a photon
            // exactly at the radius may round either way in GLSL and in Rust).
            let inside_surely = d2.iter().filter(|&&d| d <= r2 * (1.0 - 1e-6)).count();
            let inside_maybe = d2.iter().filter(|&&d| d <= r2 * (1.0 + 1e-6)).count();
            assert!(
                (inside_surely..=inside_maybe).contains(&(accepted as usize)),
                "pixel {i}: {inside_surely}..={inside_maybe} photons within the radius, {accepted} accepted"
            );
            checked += 1;
        } else {
            assert_eq!(
                accepted as usize,
                d2.len(),
                "pixel {i}: fewer than k in range, all must be taken"
            );
        }
    }
    // With k = 500 and radius 0.2 only some pixels have k photons in range; the
    // rest checked that every photon in range was taken.
    assert!(checked > 50, "only {checked} pixels had k photons in range");
}

#[test]
fn tiled_full_screen_and_masked_runs_give_identical_images() {
    let scene = common::paper_scene("glass_ball");
    // 100 x 70: the last column and row of 16-pixel tiles are cut to 4 and 6
    // pixels, less than half a tile, so their points' centres fall outside the
    // image (such tiles were once clipped whole and their pixels never searched).
    let [tiled, tiled8, full, masked] = [
        EstimateMode::Tiled { tile: 16 },
        EstimateMode::Tiled { tile: 8 },
        EstimateMode::FullScreen,
        EstimateMode::Masked { every: 2 },
    ]
    .map(|mode| render_gi(&scene, 100, 70, BuildMethod::Bitonic, mode));
    assert_eq!(tiled.image, full.image, "tiled vs full screen");
    assert_eq!(tiled8.image, full.image, "8 x 8 tiles vs full screen");
    assert_eq!(masked.image, full.image, "masked vs full screen");
    let e = tiled.estimate().cloned().unwrap();
    assert!(
        e.tile_draws < e.tiles * e.passes as u64,
        "no tile ever stopped early: {e:?}"
    );
}

#[test]
fn a_uniform_photon_plane_gives_the_analytic_irradiance() {
    // 40,000 photons of equal power spread uniformly over the 2 x 2 floor: the
    // irradiance is total power / 4 everywhere, and the radiance albedo/pi of it.
    let scene = common::fixture("photon_plane");
    let gpu = common::gpu();
    let o = RenderOptions::for_scene(&scene).direct_only();
    let out = render(&gpu, &scene, &o, &mut ()).unwrap();
    let n = 40_000usize;
    let total_power = 8.0f32;
    let mut state = 12345u32;
    let mut next = || photonmap::twins::random::rng_next(&mut state);
    let p = total_power / n as f32;
    let frames = PhotonFrames::one_frame(&gpu, 256, n as u32, |_| {
        [
            [next() * 2.0 - 1.0, 0.0, next() * 2.0 - 1.0, 0.0],
            [p, p, p, 1.0],
            [0.0; 4],
        ]
    })
    .unwrap();
    let grid = Grid::for_scene(&scene);
    let map = PhotonMap::Sorted(
        photonmap::photon::BitonicBuild::new(&gpu)
            .unwrap()
            .build(&frames, &grid, &mut Default::default())
            .unwrap(),
    );
    let est = photonmap::render::RadianceEstimate::new(&gpu, 48, 48).unwrap();
    let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
    est.run(
        &out.state.textures,
        &map,
        out.state.direct.queries(),
        k,
        max_r,
        &Default::default(),
        &mut |_| {},
    )
    .unwrap();
    est.draw_composed(
        &out.state.textures,
        &out.state.direct,
        k,
        max_r,
        false,
        true,
    )
    .unwrap();
    let img = est.composed_image();
    // Pixels seeing the middle of the floor (the estimate's disc stays on it).
    let mut sum = 0f64;
    let mut count = 0;
    for y in 12..36 {
        for x in 12..36 {
            sum += img.get(x, y)[0] as f64;
            count += 1;
        }
    }
    let mean = sum / count as f64;
    let irradiance = total_power as f64 / 4.0;
    // A k-nearest estimate is biased up by about k / (k - 1) (here accepted >= k).
    let expected = 0.6 / std::f64::consts::PI * irradiance * k as f64 / (k as f64 - 1.0);
    // Discs of radius sqrt(k / (pi density)) ~ 0.04 overlap little over the
    // 1.1 x 1.1 middle: ~ 200 independent estimates of relative error 1/sqrt(k).
    let independent = 1.1 * 1.1 / (std::f64::consts::PI * k as f64 / (n as f64 / 4.0));
    let sigma = expected / (k as f64).sqrt() / independent.sqrt();
    eprintln!("mean radiance {mean:.5}, expected {expected:.5}, sigma {sigma:.5}");
    assert!(
        (mean - expected).abs() < 4.0 * sigma + expected / k as f64,
        "mean {mean} vs {expected}"
    );
}

#[test]
fn the_software_reference_agrees_with_the_gpu() {
    use photonmap::twins::knn::{software_image, SoftwareEstimate};
    let scene = common::paper_scene("cornell_box");
    let out = render_gi(
        &scene,
        48,
        48,
        BuildMethod::Bitonic,
        EstimateMode::Tiled { tile: 16 },
    );
    // The CPU kNN-grid: the GPU's own rules, so the same image up to rounding.
    let grid_img = software_image(&out, &scene, SoftwareEstimate::KnnGrid).unwrap();
    let close = out
        .image
        .pixels
        .iter()
        .zip(&grid_img.pixels)
        .filter(|(a, b)| (0..3).all(|c| (a[c] - b[c]).abs() <= 1e-4 * a[c].abs().max(1e-3)))
        .count();
    assert!(
        close * 1000 >= out.image.pixels.len() * 999,
        "{close} of {} pixels agree",
        out.image.pixels.len()
    );
    // Jensen's kd-tree takes exactly the k nearest where the kNN-grid takes at
    // least k: the same picture, slightly less blurred. Their means stay close.
    let kd = software_image(&out, &scene, SoftwareEstimate::KdTree).unwrap();
    let (a, b) = (out.image.mean(), kd.mean());
    for c in 0..3 {
        assert!(
            (a[c] - b[c]).abs() < 0.03 * a[c],
            "channel {c}: GPU mean {} vs kd-tree {}",
            a[c],
            b[c]
        );
    }
}

#[test]
fn faithful_mode_renders_the_same_image() {
    // --faithful: random-number texture (the hash's numbers), float addressing,
    // every record sorted, read-back before routing. Same photons, same map.
    let scene = common::paper_scene("glass_ball");
    for build in [BuildMethod::Bitonic, BuildMethod::Stencil] {
        let gpu = common::gpu();
        let mut images = Vec::new();
        for faithful in [false, true] {
            let mut o = RenderOptions::for_scene(&scene);
            (o.width, o.height) = (64, 48);
            o.method = Method::PhotonMap(PhotonMapOptions {
                photons: PhotonConfig {
                    build,
                    faithful,
                    ..PhotonConfig::default()
                },
                ..PhotonMapOptions::default()
            });
            images.push(render(&gpu, &scene, &o, &mut ()).unwrap().image);
        }
        assert_eq!(
            images[0], images[1],
            "{build:?}: faithful and default differ"
        );
    }
}

/// The leak tests (disc, visibility, both) on the GPU equal the CPU kNN-grid
/// run with the same tests, pixel for pixel.
#[test]
fn gpu_leak_tests_equal_their_cpu_twins() {
    use photonmap::render::radiance_estimate::LeakTest;
    use photonmap::twins::knn::{knn_grid_filtered, photon_visible};
    let gpu = common::gpu();
    for (name, w, h) in [("ring", 64, 48), ("cornell_box", 48, 48)] {
        let scene = common::paper_scene(name);
        for leak in [
            LeakTest::Disc,
            LeakTest::Visibility,
            LeakTest::DiscAndVisibility,
        ] {
            let mut o = RenderOptions::for_scene(&scene);
            (o.width, o.height, o.seed) = (w, h, 3);
            let gi = o.photon_map_mut().unwrap();
            gi.estimate.leak = leak;
            gi.estimate.budget = 48;
            let out = render(&gpu, &scene, &o, &mut ()).unwrap();
            let cpu_map = CpuPhotonMap::from_gpu(out.map().unwrap());
            let normal = out.state.direct.diffuse_normal.read_f32();
            let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
            let thickness = photonmap::layout::DISC_THICKNESS * max_r;
            let results = gpu_results(&out);
            assert_agrees_with_twin(&format!("{name} {leak:?}"), &results, 100, |i, x| {
                let nf = Vec3::from_slice(&normal[4 * i..]);
                let accept = |p: Vec3| {
                    let disc = !matches!(leak, LeakTest::Disc | LeakTest::DiscAndVisibility)
                        || (p - x).dot(nf).abs() <= thickness;
                    let seen = !matches!(leak, LeakTest::Visibility | LeakTest::DiscAndVisibility)
                        || photon_visible(&scene, x, nf, p);
                    disc && seen
                };
                knn_grid_filtered(&cpu_map, x, k, max_r, &accept)
            });
        }
    }
}

/// The search's ways of visiting cells (skipping cells beyond the reach,
/// reading a face row's cells as one range) leave the result bit for bit the
/// paper search's, on both builds; the paper search examines exactly the
/// photons its CPU twin does, and the others examine fewer.
#[test]
fn culled_searches_end_in_the_paper_search_s_state_bit_for_bit() {
    use photonmap::twins::knn::knn_grid_counted;
    for (name, w, h) in PAPER_SCENES {
        let scene = common::paper_scene(name);
        for build in [BuildMethod::Bitonic, BuildMethod::Stencil] {
            let mut states = Vec::new();
            for (cull, runs) in [(false, false), (true, false), (true, true)] {
                let gpu = common::gpu();
                let mut o = gi_options(&scene, w, h, build, EstimateMode::Tiled { tile: 16 });
                let gi = o.photon_map_mut().unwrap();
                (gi.estimate.cull, gi.estimate.runs) = (cull, runs);
                let out = render(&gpu, &scene, &o, &mut ()).unwrap();
                let est = out.radiance_estimate().unwrap();
                let twin = (cull, runs) == (false, false);
                let cpu_map = twin.then(|| CpuPhotonMap::from_gpu(out.map().unwrap()));
                let pos = out.state.direct.diffuse_position.read_f32();
                states.push((
                    est.flux.read_f32(),
                    est.cursor.read_i32(),
                    est.done.read_i32(),
                    out.estimate().cloned().unwrap().work,
                ));
                let Some(cpu_map) = cpu_map else { continue };
                let done = &states.last().unwrap().2;
                let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
                let mut checked = 0;
                for i in (0..pos.len() / 4).filter(|&i| pos[4 * i + 3] > 0.0) {
                    let x = Vec3::from_slice(&pos[4 * i..]);
                    let (_, examined) = knn_grid_counted(&cpu_map, x, k, max_r, &|_| true);
                    assert_eq!(
                        done[4 * i + 1] as u64,
                        examined,
                        "{name} {build:?} pixel {i}: photons examined against the twin's"
                    );
                    checked += 1;
                }
                assert!(checked > (w * h / 3) as usize, "{name}: {checked} queries");
            }
            let (flux0, cursor0, done0, work0) = &states[0];
            for (v, (flux, cursor, done, work)) in states.iter().enumerate().skip(1) {
                assert!(
                    flux.iter()
                        .zip(flux0)
                        .all(|(a, b)| a.to_bits() == b.to_bits()),
                    "{name} {build:?} variant {v}: flux or radius differs"
                );
                for i in 0..cursor.len() / 4 {
                    assert_eq!(
                        cursor[4 * i],
                        cursor0[4 * i],
                        "{name} {build:?} variant {v} pixel {i}: accepted"
                    );
                    assert_eq!(
                        done[4 * i],
                        done0[4 * i],
                        "{name} {build:?} variant {v} pixel {i}: done"
                    );
                    assert!(
                        done[4 * i + 1] <= done0[4 * i + 1] && done[4 * i + 1] >= cursor[4 * i],
                        "{name} {build:?} variant {v} pixel {i}: examined {} against the paper's {} and {} accepted",
                        done[4 * i + 1],
                        done0[4 * i + 1],
                        cursor[4 * i]
                    );
                }
                assert!(
                    work.steps < work0.steps,
                    "{name} {build:?} variant {v}: {} steps against the paper's {}",
                    work.steps,
                    work0.steps
                );
            }
            eprintln!(
                "{name} {build:?}: steps {} / {} / {}, photons examined {} / {} / {}",
                states[0].3.steps,
                states[1].3.steps,
                states[2].3.steps,
                states[0].3.photons_examined,
                states[1].3.photons_examined,
                states[2].3.photons_examined
            );
        }
    }
}
