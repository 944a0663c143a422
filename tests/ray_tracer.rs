//! The fragment-program ray tracer: the stochastic Fresnel choice converges to
//! the split tree, emitters show their radiance, and direct light matches a
//! closed form.

mod common;

use glam::Vec3;
use photonmap::reference::ray_trace::{expected_moments, eye_ray_at};
use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::{load_scene_str, Scene};

/// GLASS BALL's geometry under a point light, so direct light is deterministic
/// and all the randomness left is the reflect-or-refract choice.
fn glass_scene(ior: f32) -> Scene {
    let text = format!(
        r#"
[camera]
position = [0.0, 2.0, 5.5]
look_at = [0.0, 0.6, 0.0]
vfov = 24.0
width = 40
height = 30
[render]
max_specular_depth = 8
[materials]
floor = {{ type = "diffuse", albedo = [0.75, 0.75, 0.75] }}
glass = {{ type = "glass", ior = {ior} }}
[[shape]]
type = "parallelogram"
corner = [-3.0, 0.0, -3.0]
edge1 = [0.0, 0.0, 6.0]
edge2 = [6.0, 0.0, 0.0]
material = "floor"
[[shape]]
type = "sphere"
center = [0.0, 0.8, 0.0]
radius = 0.8
material = "glass"
[[light]]
type = "point"
position = [-1.0, 3.5, 2.5]
intensity = [10.0, 10.0, 10.0]
"#
    );
    load_scene_str(&text, std::path::Path::new("glass_point.toml")).unwrap()
}

/// Per pixel: the CPU's expected value, the exact variance of one GPU sample,
/// and whether the pixel is well-conditioned: its expectation barely moves when
/// the eye ray moves by 1/100 pixel (at a grazing silhouette f32 rounding in GLSL
/// and Rust can send a path down different branches, so no comparison is fair).
fn cpu_expectation(scene: &Scene) -> (Image, Image, Vec<bool>) {
    let (w, h) = (scene.camera.width, scene.camera.height);
    let depth = scene.render.max_specular_depth;
    let (mut mean, mut var) = (Image::new(w, h), Image::new(w, h));
    let mut stable = vec![true; (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            let at = |dx: f32, dy: f32| {
                let (o, d) = eye_ray_at(scene, w, h, x as f32 + 0.5 + dx, y as f32 + 0.5 + dy);
                expected_moments(scene, o, d, depth, 1)
            };
            let (m1, m2) = at(0.0, 0.0);
            let i = (y * w + x) as usize;
            mean.pixels[i] = m1.to_array();
            var.pixels[i] = (m2 - m1 * m1).max(Vec3::ZERO).to_array();
            for (dx, dy) in [(0.01, 0.0), (-0.01, 0.0), (0.0, 0.01), (0.0, -0.01)] {
                let (p1, _) = at(dx, dy);
                if (p1 - m1).abs().max_element() > 0.05 * m1.max_element() + 1e-4 {
                    stable[i] = false;
                }
            }
        }
    }
    (mean, var, stable)
}

/// Fraction of well-conditioned pixel channels where the GPU mean over `n`
/// seeds is more than 4.5 standard errors (exact, from the CPU) from the CPU's
/// expectation.
fn failing(gpu_mean: &Image, n: usize, cpu: &(Image, Image, Vec<bool>)) -> f64 {
    let (expect, var, stable) = cpu;
    let (mut bad, mut tested) = (0, 0);
    for (i, _) in stable.iter().enumerate().filter(|(_, &s)| s) {
        for c in 0..3 {
            let (m, e) = (gpu_mean.pixels[i][c], expect.pixels[i][c]);
            let floor = 1e-3 * e.abs() + 1e-6; // f32 rounding between GLSL and Rust
            let se = (var.pixels[i][c] / n as f32 + floor * floor).sqrt();
            tested += 1;
            if ((m - e) / se).abs() > 4.5 {
                bad += 1;
            }
        }
    }
    bad as f64 / tested as f64
}

#[test]
fn stochastic_fresnel_choice_converges_to_the_split_tree() {
    let gpu = common::gpu();
    let scene = glass_scene(1.5);
    let n = 256;
    let images: Vec<Image> = (0..n)
        .map(|seed| {
            let mut o = RenderOptions::for_scene(&scene).direct_only();
            o.seed = seed + 1;
            render(&gpu, &scene, &o, &mut ()).unwrap().image
        })
        .collect();
    let mean = Image::average(&images);
    // The choice is really random: some pixels vary between seeds.
    assert!(
        images.iter().any(|im| im.pixels != images[0].pixels),
        "no pixel varies: nothing stochastic was tested"
    );

    let cpu = cpu_expectation(&scene);
    let stable = cpu.2.iter().filter(|&&s| s).count();
    let right = failing(&mean, n as usize, &cpu);
    // A different ior changes the expectation: the test must notice.
    let wrong = failing(&mean, n as usize, &cpu_expectation(&glass_scene(1.6)));
    eprintln!(
        "{stable} of {} pixels well-conditioned; channels beyond 4.5 standard errors: {:.3}% against the split tree, {:.3}% against ior 1.6",
        cpu.2.len(),
        100.0 * right,
        100.0 * wrong
    );
    assert!(
        stable as f64 > 0.9 * cpu.2.len() as f64,
        "too few pixels compared"
    );
    // At 4.5 sigma a correct estimator fails ~1e-5 of channels.
    assert!(
        right == 0.0,
        "GPU mean departs from the split tree in {:.3}% of channels",
        100.0 * right
    );
    // The ball fills about a tenth of the frame; a wrong ior must show in a good part of it.
    assert!(
        wrong > 0.01,
        "a 1.6 ior expectation was not told apart ({:.3}%)",
        100.0 * wrong
    );
}

#[test]
fn an_emitter_seen_directly_shows_its_radiance() {
    let gpu = common::gpu();
    let scene = common::paper_scene("cornell_box");
    let mut o = RenderOptions::for_scene(&scene).direct_only();
    (o.width, o.height) = (64, 64);
    let img = render(&gpu, &scene, &o, &mut ()).unwrap().image;
    let at_light = img
        .pixels
        .iter()
        .filter(|p| **p == [25.0, 25.0, 25.0])
        .count();
    assert!(at_light >= 4, "{at_light} pixels show the light's Le = 25");
    // Nothing else is brighter than the light.
    assert!(img.pixels.iter().flatten().all(|&v| v <= 25.0));
}

#[test]
fn direct_light_from_a_point_light_matches_the_closed_form() {
    // A floor under a point light straight above the pixel seen at the image centre:
    // L = albedo / pi * I * cos / r^2 with cos = 1.
    let text = r#"
[camera]
position = [0.0, 5.0, 0.001]
look_at = [0.0, 0.0, 0.0]
vfov = 10.0
width = 9
height = 9
[materials]
floor = { type = "diffuse", albedo = [0.5, 0.25, 1.0] }
[[shape]]
type = "parallelogram"
corner = [-10.0, 0.0, -10.0]
edge1 = [0.0, 0.0, 20.0]
edge2 = [20.0, 0.0, 0.0]
material = "floor"
[[light]]
type = "point"
position = [0.0, 2.0, 0.0]
intensity = [8.0, 8.0, 8.0]
"#;
    let scene = load_scene_str(text, std::path::Path::new("point.toml")).unwrap();
    let gpu = common::gpu();
    let img = render(
        &gpu,
        &scene,
        &RenderOptions::for_scene(&scene).direct_only(),
        &mut (),
    )
    .unwrap()
    .image;
    let centre = Vec3::from(img.get(4, 4));
    let expect = Vec3::new(0.5, 0.25, 1.0) / std::f32::consts::PI * 8.0 / 4.0;
    assert!(
        (centre - expect).abs().max_element() < 1e-3 * expect.max_element(),
        "{centre} vs {expect}"
    );
}

#[test]
fn samples_per_pixel_cut_noise_and_antialias_edges() {
    let gpu = common::gpu();
    let run = |scene: &Scene, spp: u32, seed: u32| {
        let mut o = RenderOptions::for_scene(scene).direct_only();
        (o.width, o.height, o.spp, o.seed) = (64, 48, spp, seed);
        render(&gpu, scene, &o, &mut ()).unwrap().image
    };
    // Seed-to-seed difference (soft shadows, the glass choice) falls roughly as 1/sqrt(spp).
    let glass = common::paper_scene("glass_ball");
    let d1 = common::rmse(&run(&glass, 1, 1), &run(&glass, 1, 2));
    let d16 = common::rmse(&run(&glass, 16, 1), &run(&glass, 16, 2));
    eprintln!("seed-to-seed RMSE: {d1:.5} at 1 spp, {d16:.5} at 16 spp");
    assert!(d16 < d1 / 2.0, "16 spp: {d16}, 1 spp: {d1}");
    // The light's edge: with one ray per pixel centre an emitter pixel is Le or
    // not; with 16 jittered samples, border pixels take values in between.
    let cornell = common::paper_scene("cornell_box");
    let between = |img: &photonmap::render::Image| {
        img.pixels
            .iter()
            .filter(|p| p[0] > 3.0 && p[0] < 22.0)
            .count()
    };
    let (one, many) = (
        between(&run(&cornell, 1, 1)),
        between(&run(&cornell, 16, 1)),
    );
    assert!(
        many > one + 4,
        "pixels between ceiling and light: {one} at 1 spp, {many} at 16 spp"
    );
}
