//! Stochastic progressive photon mapping: the gather-and-update kernel equals
//! its CPU twin, and the method converges to the exact answer, shown against
//! analytic scenes and against an independent CPU path tracer.

use crate::common;

use glam::Vec3;
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::render::software::CpuPhotonMap;
use photonmap::render::sppm::{render_sppm, Sppm, SppmOptions};
use photonmap::render::{render, Image, Method, PhotonMapOptions, RenderOptions};
use photonmap::scene::{load_scene_str, Material, Scene};
use photonmap::timing::Timings;
use photonmap::twins::sppm::{update, PixelState, VisiblePoint};

fn options(scene: &Scene, w: u32, h: u32, seed: u32, build: BuildMethod) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (w, h, seed);
    o.method = Method::PhotonMap(PhotonMapOptions {
        photons: PhotonConfig {
            build,
            ..PhotonConfig::default()
        },
        ..PhotonMapOptions::default()
    });
    o
}

/// After one iteration, the next one's GPU update against the twin run on the
/// same photons, visible points and state: counts agree exactly but where a
/// photon sits on the radius to rounding, flux and radius to float precision.
#[test]
fn the_gather_and_update_kernel_equals_its_cpu_twin() {
    let gpu = common::gpu();
    use photonmap::render::radiance_estimate::LeakTest;
    for (name, build, leak) in [
        ("glass_ball", BuildMethod::Bitonic, LeakTest::None),
        ("cornell_box", BuildMethod::Stencil, LeakTest::None),
        ("ring", BuildMethod::Bitonic, LeakTest::Visibility),
    ] {
        let scene = common::paper_scene(name);
        let sppm_options = SppmOptions {
            photons_per_iteration: 1 << 15,
            leak: Some(leak),
            ..SppmOptions::default()
        };
        let o = options(&scene, 64, 48, 5, build);
        let mut run = Sppm::new(&gpu, &scene, &o, &sppm_options).unwrap();
        let mut timings = Timings::default();
        run.iterate(&mut timings, &mut ()).unwrap();
        let (flux0, sums0) = (
            common::texels(&run.state.flux),
            common::texels(&run.state.sums),
        );
        let first_radius2 = run.cell * run.cell;
        run.iterate(&mut timings, &mut ()).unwrap();
        let (flux1, sums1) = (
            common::texels(&run.state.flux),
            common::texels(&run.state.sums),
        );
        let map = CpuPhotonMap::from_gpu(run.map.as_ref().unwrap());
        let d = &run.direct;
        let (direct, pos, normal, through) = (
            common::texels(&d.radiance),
            common::texels(&d.diffuse_position),
            common::texels(&d.diffuse_normal),
            common::texels(&d.diffuse_throughput),
        );
        let (mut gathering, mut count_differs, mut worst) = (0, 0, 0f32);
        for i in 0..flux0.len() {
            let mat = normal[i][3] as i32 - 1;
            let vp = (pos[i][3] > 0.0 && mat >= 0).then(|| {
                let Material::Diffuse { albedo } = run.scene().materials[mat as usize] else {
                    panic!("a visible point on a non-diffuse surface")
                };
                VisiblePoint {
                    position: common::v3(pos[i]),
                    normal: common::v3(normal[i]),
                    albedo,
                    throughput: common::v3(through[i]),
                }
            });
            let before = PixelState {
                tau: common::v3(flux0[i]),
                radius2: flux0[i][3],
                direct: common::v3(sums0[i]),
                count: sums0[i][3],
            };
            let accept = |vp: &VisiblePoint, p: Vec3| {
                leak == LeakTest::None
                    || photonmap::twins::knn::photon_visible(run.scene(), vp.position, vp.normal, p)
            };
            let cpu = update(
                &map,
                before,
                common::v3(direct[i]),
                vp,
                0.7,
                first_radius2,
                &accept,
            );
            if sums1[i][3] > sums0[i][3] {
                gathering += 1;
            }
            if cpu.count != sums1[i][3] {
                count_differs += 1;
                continue;
            }
            let rel = |a: f32, b: f32| (a - b).abs() / (a.abs().max(b.abs()) + 1e-6);
            for c in 0..3 {
                worst = worst.max(rel(cpu.tau[c], flux1[i][c]));
                worst = worst.max(rel(cpu.direct[c], sums1[i][c]));
            }
            worst = worst.max(rel(cpu.radius2, flux1[i][3]));
        }
        eprintln!(
            "{name} ({build:?}, {leak:?}): {gathering} of {} pixels gathered photons; counts differ at {count_differs}; largest relative difference {worst:.2e}",
            flux0.len()
        );
        assert!(
            gathering > flux0.len() / 4,
            "{name}: too few pixels gathered"
        );
        assert!(
            count_differs * 200 <= flux0.len(),
            "{name}: {count_differs} counts differ"
        );
        assert!(worst < 1e-4, "{name}: {worst}");
    }
}

fn sppm_image(scene: &Scene, w: u32, h: u32, seed: u32, o: &SppmOptions) -> Image {
    let gpu = common::gpu();
    render_sppm(
        &gpu,
        scene,
        &options(scene, w, h, seed, BuildMethod::Bitonic),
        o,
        &mut (),
    )
    .unwrap()
    .image
}

/// The mean of independent samples and its standard error (from their spread).
fn mean_and_standard_error(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let mean = x.iter().sum::<f64>() / n;
    let var = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
    (mean, (var / n).sqrt())
}

fn mean_of(img: &Image) -> f64 {
    img.mean().iter().sum::<f64>() / 3.0
}

/// The furnace: a closed diffuse sphere (albedo rho, radius R) with a point
/// light of intensity I at its centre has L = rho I / (pi R^2 (1 - rho))
/// everywhere: half by shadow rays, half by photons. By Archimedes' hat-box
/// theorem the gather disc on the sphere has area exactly pi R^2, so SPPM is
/// unbiased here at every iteration and all its error is noise.
#[test]
fn the_furnace_converges_to_its_analytic_value() {
    let scene = common::fixture("furnace");
    let o = SppmOptions {
        iterations: 64,
        photons_per_iteration: 1 << 14,
        initial_radius: Some(0.1),
        ..SppmOptions::default()
    };
    let img = sppm_image(&scene, 32, 32, 3, &o);
    let expected = 0.5 / (std::f64::consts::PI * 0.5);
    let mean = mean_of(&img);
    eprintln!(
        "furnace: SPPM mean {mean:.5} against {expected:.5} ({:+.3}%)",
        100.0 * (mean / expected - 1.0)
    );
    assert!((mean / expected - 1.0).abs() < 0.01, "{mean} vs {expected}");
}

/// The form factor from a differential area to a parallel rectangle of sides
/// a x b whose corner lies above it at height h (the classic closed form).
fn corner_form_factor(a: f64, b: f64, h: f64) -> f64 {
    let (x, y) = (a / h, b / h);
    let (sx, sy) = ((1.0 + x * x).sqrt(), (1.0 + y * y).sqrt());
    (x / sx * (y / sx).atan() + y / sy * (x / sy).atan()) / (2.0 * std::f64::consts::PI)
}

/// Irradiance at (x, z) on the floor under the light [-s, s]^2 at height h of radiance le.
fn plane_irradiance(x: f64, z: f64, s: f64, h: f64, le: f64) -> f64 {
    let mut f = 0.0;
    for (dx, dz) in [
        (s - x, s - z),
        (s + x, s - z),
        (s - x, s + z),
        (s + x, s + z),
    ] {
        f += corner_form_factor(dx, dz, h);
    }
    std::f64::consts::PI * le * f
}

/// A floor (albedo 0.5) under a parallel square area light 20 x 20 at height
/// 1: the photon half alone (direct light by photons, no shadow rays) must
/// give the closed-form irradiance, pixel by pixel averaged over the view.
#[test]
fn a_uniformly_lit_plane_gives_its_analytic_irradiance() {
    let scene = common::fixture("lit_plane");
    let o = SppmOptions {
        iterations: 32,
        photons_per_iteration: 1 << 15,
        direct: photonmap::render::sppm::DirectLighting::Photons,
        ..SppmOptions::default()
    };
    // The expected image: L = rho E / pi at each pixel centre's floor point.
    let mut expected = 0.0;
    for y in 0..32 {
        for x in 0..32 {
            let (origin, d) = photonmap::twins::ray_trace::eye_ray(&scene, 32, 32, x, y);
            let t = -origin.y / d.y;
            let p = origin + t * d;
            expected += 0.5 * plane_irradiance(p.x as f64, p.z as f64, 10.0, 1.0, 1.0)
                / std::f64::consts::PI;
        }
    }
    expected /= 1024.0;
    // Four independent renders: their spread measures the noise of their mean.
    let means: Vec<f64> = (1..=4)
        .map(|seed| mean_of(&sppm_image(&scene, 32, 32, seed, &o)))
        .collect();
    let mean = means.iter().sum::<f64>() / 4.0;
    let sd = (means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / 3.0).sqrt();
    let sigma = sd / 2.0;
    eprintln!(
        "lit plane: SPPM (direct by photons) {mean:.5} +- {sigma:.5} against {expected:.5} ({:+.3}%; runs {means:.4?})",
        100.0 * (mean / expected - 1.0)
    );
    assert!(
        sigma < 0.005 * expected,
        "the test lost its power: sigma {sigma}"
    );
    assert!(
        (mean - expected).abs() < 4.0 * sigma,
        "{mean} vs {expected} +- {sigma}"
    );
}

/// A closed diffuse box (coloured walls) lit by a point light and a ceiling
/// area light: SPPM and the independent CPU path tracer (next-event
/// estimation) must agree block by block within their combined noise.
#[test]
fn sppm_agrees_with_an_independent_path_tracer() {
    let scene = common::fixture("two_light_box");
    let t0 = std::time::Instant::now();
    let pt = photonmap::twins::path_trace::path_trace(&scene, 32, 32, 1024, 11);
    let pt_seconds = t0.elapsed().as_secs_f64();
    let o = SppmOptions {
        iterations: 128,
        photons_per_iteration: 1 << 13,
        initial_radius: Some(0.03),
        ..SppmOptions::default()
    };
    let t0 = std::time::Instant::now();
    let runs = [
        sppm_image(&scene, 32, 32, 1, &o),
        sppm_image(&scene, 32, 32, 2, &o),
    ];
    let sppm_seconds = t0.elapsed().as_secs_f64();
    let (n, chi2_n, worst) = common::blocks_against_path_tracer(&pt, [&runs[0], &runs[1]]);
    eprintln!(
        "two-light box: {n} blocks, chi^2/n = {chi2_n:.2}, largest relative difference {:.2}% (path tracer 1024 spp in {pt_seconds:.1} s, SPPM 2 x 128 iterations in {sppm_seconds:.1} s)",
        100.0 * worst
    );
    assert!(chi2_n < 3.0, "chi^2/n = {chi2_n}");
}

/// The furnace seen from inside glass (`scenes/tests/furnace_in_glass.toml`):
/// the camera and the point light at the centre of a glass ball in the
/// closed diffuse sphere. The ball is lossless, so the walls' radiance stays
/// the furnace's uniform L = rho I / (pi R^2 (1 - rho)), and a camera in the
/// glass sees it ior^2 = 2.25 times as bright (radiance's (eta_i / eta_t)^2
/// where the eye path leaves the glass). The field is uniform, so SPPM and
/// the paper's kNN estimate are unbiased here (hat-box theorem, as in the
/// furnace) and their error is noise: each method's mean over 8 seeds must
/// lie within 4 of its standard errors (from the seeds' spread) of the
/// closed form, and that error must be small enough to tell ior^2 from ior.
#[test]
fn the_furnace_seen_from_inside_glass_is_ior_squared_as_bright() {
    let scene = common::fixture("furnace_in_glass");
    let expected = 1.5f64.powi(2) * 0.5 / (std::f64::consts::PI * 0.5);
    let sppm = SppmOptions {
        iterations: 32,
        photons_per_iteration: 1 << 14,
        initial_radius: Some(0.1),
        ..SppmOptions::default()
    };
    let gpu = common::gpu();
    let methods: [(&str, &dyn Fn(u32) -> Image); 2] = [
        ("SPPM", &|seed| sppm_image(&scene, 32, 32, seed, &sppm)),
        ("the paper's method", &|seed| {
            let mut o = RenderOptions::for_scene(&scene);
            (o.width, o.height, o.seed) = (32, 32, seed);
            render(&gpu, &scene, &o, &mut ()).unwrap().image
        }),
    ];
    for (name, image) in methods {
        let ratios: Vec<f64> = (1..=8)
            .map(|seed| mean_of(&image(seed)) / expected)
            .collect();
        let (mean, se) = mean_and_standard_error(&ratios);
        eprintln!("furnace in glass, {name}: {mean:.4} +- {se:.4} of ior^2 L (seeds {ratios:.4?})");
        assert!(
            se < 0.01,
            "{name}: the test lost its power (standard error {se})"
        );
        assert!(
            (mean - 1.0).abs() < 4.0 * se,
            "{name}: {mean} +- {se} of ior^2 L"
        );
    }
}

/// SPPM of `scene_name` at the size of two independent Mitsuba runs
/// (`reference_images/<dir>/reference_run{1,2}.exr`, from `bench mitsuba
/// --mitsuba-reference`), 8 seeds of 32 iterations, against the runs: block
/// by block (4 x 4 pixels) the seeds' mean must meet the runs' within the
/// bound `block_chi2` derives from the seeds' spread, and the image's
/// energy must lie within 1% and within 4 standard errors.
fn assert_sppm_meets_mitsuba_runs(scene_name: &str, dir: &str) {
    let scene = common::paper_scene(scene_name);
    let run = |k: u32| {
        let path = common::root().join(format!("reference_images/{dir}/reference_run{k}.exr"));
        Image::read_exr(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    };
    let runs = [run(1), run(2)];
    let (w, h) = (runs[0].width, runs[0].height);
    let sppm = SppmOptions {
        iterations: 32,
        photons_per_iteration: 1 << 13,
        // A pixel's footprint at 32 x 32 would blur edges into their
        // neighbours' blocks; this is about its footprint at 128 x 128.
        initial_radius: Some(0.03),
        ..SppmOptions::default()
    };
    let t0 = std::time::Instant::now();
    let images: Vec<Image> = (1..=8)
        .map(|seed| sppm_image(&scene, w, h, seed, &sppm))
        .collect();
    let seconds = t0.elapsed().as_secs_f64();
    let (chi2, blocks, bound) = common::block_chi2_against_runs(&images, [&runs[0], &runs[1]], 4);
    let reference = 0.5 * (mean_of(&runs[0]) + mean_of(&runs[1]));
    let ratios: Vec<f64> = images.iter().map(|i| mean_of(i) / reference).collect();
    let (energy, se) = mean_and_standard_error(&ratios);
    eprintln!(
        "{dir} {w} x {h}: {blocks} blocks, chi^2/n = {chi2:.2} (bound {bound:.2}); energy {energy:.4} +- {se:.4} of Mitsuba's (8 x 32 SPPM iterations in {seconds:.1} s)"
    );
    assert!(
        chi2 < bound,
        "chi^2/n = {chi2} over {blocks} blocks, bound {bound}"
    );
    assert!(
        (energy - 1.0).abs() < 0.01 && (energy - 1.0).abs() < 4.0 * se.max(1e-4),
        "energy {energy} +- {se} of the reference's"
    );
}

/// A block and the floor inside a glass tank (`scenes/variants/glass_tank.toml`
/// at 32 x 32, an eighth of its size) against Mitsuba 3's path tracer: the
/// reference is two independent 90 s runs (`reference_images/glass_tank/`,
/// made by `bench mitsuba --mitsuba-reference`). The camera sees the block and
/// the floor in the tank only through the glass, so radiance's (eta_i /
/// eta_t)^2 decides them: without it they read 2.25 times as bright. Block by
/// block (4 x 4 pixels), SPPM's mean over 8 seeds must meet the reference
/// within the bound `block_chi2` derives from the seeds' spread, and the
/// image's energy must lie within 1% and within 4 standard errors.
#[test]
fn a_block_in_a_glass_tank_meets_mitsubas_path_tracer() {
    assert_sppm_meets_mitsuba_runs("variants/glass_tank", "glass_tank");
}

/// CORNELL BOX with a rough gold sphere (Trowbridge-Reitz alpha 0.2) and a
/// smooth aluminium one (`scenes/tests/metal_box.toml` at 32 x 32, a quarter
/// of its size) against Mitsuba 3's path tracer (`roughconductor`, GGX;
/// `conductor`): the reference is two independent 90 s runs
/// (`reference_images/metal_box/`). The gold sphere is seen by the eye
/// paths' glossy step (shadow rays weighted by the BSDF and a sample of the
/// lobe, by the balance heuristic), and lights the floor by photons that
/// left it by sampling. Block by block (4 x 4 pixels), SPPM's mean over 8
/// seeds must meet the reference within the bound `block_chi2` derives from
/// the seeds' spread, and the image's energy must lie within 1% and within
/// 4 standard errors.
#[test]
fn rough_and_smooth_metals_meet_mitsubas_path_tracer() {
    assert_sppm_meets_mitsuba_runs("tests/metal_box", "metal_box");
}

/// Energy: inside a closed diffuse sphere (radius 1, albedo rho) with a point
/// light of intensity I off its centre, the radiance integrated over the
/// sphere is rho 4 pi I / (pi (1 - rho)) = 4 for rho = 1/2, I = 1, wherever
/// the light is. Six 90-degree views from the centre cover the sphere; each
/// pixel sees the area R^2 d(omega).
#[test]
fn the_radiance_of_a_closed_scene_integrates_to_the_lights_power() {
    let base = include_str!("../../scenes/tests/furnace.toml").replace(
        "position = [0.0, 0.0, 0.0]\nintensity",
        "position = [0.35, 0.2, -0.15]\nintensity",
    );
    assert_ne!(
        base,
        include_str!("../../scenes/tests/furnace.toml"),
        "the light moved off centre"
    );
    let faces = [
        (Vec3::X, Vec3::Y),
        (-Vec3::X, Vec3::Y),
        (Vec3::Y, Vec3::Z),
        (-Vec3::Y, Vec3::Z),
        (Vec3::Z, Vec3::Y),
        (-Vec3::Z, Vec3::Y),
    ];
    let (w, iterations, photons) = (32u32, 32u32, 1u32 << 13);
    let o = SppmOptions {
        iterations,
        photons_per_iteration: photons,
        initial_radius: Some(0.15),
        ..SppmOptions::default()
    };
    let mut total = 0.0;
    for (i, (look, up)) in faces.iter().enumerate() {
        let mut scene =
            load_scene_str(&base, std::path::Path::new("off_centre_furnace.toml")).unwrap();
        scene.camera.position = Vec3::ZERO;
        scene.camera.look_at = *look;
        scene.camera.up = *up;
        scene.camera.vfov_degrees = 90.0;
        let img = sppm_image(&scene, w, w, 1 + i as u32, &o);
        for y in 0..w {
            for x in 0..w {
                let u = (x as f64 + 0.5) / w as f64 * 2.0 - 1.0;
                let v = (y as f64 + 0.5) / w as f64 * 2.0 - 1.0;
                let d_omega = (2.0 / w as f64).powi(2) / (1.0 + u * u + v * v).powf(1.5);
                let l = img.get(x, y).iter().map(|&c| c as f64).sum::<f64>() / 3.0;
                total += l * d_omega;
            }
        }
    }
    // Noise: the photon half is the stored photons' power, and a photon of
    // this grey furnace is stored on average rho/(1 - rho) = 1 time with
    // variance rho/(1 - rho)^2 = 2; that sum's relative sd over every
    // iteration's batch, on half of the total.
    let sigma = 4.0 * 0.5 * (2.0f64 / (photons as f64 * iterations as f64)).sqrt();
    eprintln!("closed sphere: integrated radiance {total:.4} against 4 (+- {sigma:.4})");
    assert!((total - 4.0).abs() < 4.0 * sigma, "{total}");
}

/// The error falls with iterations as theory says: in the furnace SPPM is
/// unbiased, so its error is noise, whose RMSE falls as i^(-alpha/2)
/// (Knaus and Zwicker 2011): -0.35 for alpha = 0.7.
#[test]
fn the_error_falls_with_the_slope_theory_predicts() {
    let gpu = common::gpu();
    let scene = common::fixture("furnace");
    let o = SppmOptions {
        photons_per_iteration: 1 << 11,
        initial_radius: Some(0.25),
        ..SppmOptions::default()
    };
    let expected = 1.0 / std::f32::consts::PI;
    let mut points = Vec::new();
    let mut run = Sppm::new(
        &gpu,
        &scene,
        &options(&scene, 24, 24, 9, BuildMethod::Bitonic),
        &o,
    )
    .unwrap();
    let mut timings = Timings::default();
    for k in 0..=8 {
        while run.iteration < 1 << k {
            run.iterate(&mut timings, &mut ()).unwrap();
        }
        let img = run.image().unwrap();
        let se: f64 = img
            .pixels
            .iter()
            .map(|p| ((p[0] + p[1] + p[2]) / 3.0 - expected) as f64)
            .map(|e| e * e)
            .sum();
        points.push((run.iteration as f64, (se / img.pixels.len() as f64).sqrt()));
    }
    // Least squares over i = 4 .. 256 in log-log.
    let fit: Vec<(f64, f64)> = points[2..].iter().map(|(i, e)| (i.ln(), e.ln())).collect();
    let n = fit.len() as f64;
    let (sx, sy) = fit.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let slope = fit.iter().map(|(x, y)| (x - mx) * (y - my)).sum::<f64>()
        / fit.iter().map(|(x, _)| (x - mx).powi(2)).sum::<f64>();
    eprintln!("furnace RMSE by iteration: {points:.4?}");
    eprintln!("log-log slope of RMSE against iterations: {slope:.3} (theory -0.35)");
    assert!((slope + 0.35).abs() < 0.1, "slope {slope}");
}
