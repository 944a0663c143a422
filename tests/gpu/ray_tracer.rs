//! The fragment-program ray tracer: the stochastic Fresnel choice converges to
//! the split tree, emitters show their radiance, and direct light matches a
//! closed form.

use crate::common;

use glam::Vec3;
use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::{load_scene_str, Scene};
use photonmap::twins::ray_trace::{expected_moments, eye_ray_at};

/// GLASS BALL's geometry under a point light, so direct light is deterministic
/// and all the randomness left is the reflect-or-refract choice.
fn glass_scene(ior: f32) -> Scene {
    load_scene_str(&glass_text(ior), &common::fixture_file("glass_point")).unwrap()
}

/// scenes/tests/glass_point.toml with glass of `ior`.
fn glass_text(ior: f32) -> String {
    common::replace_once(
        &common::fixture_text("glass_point"),
        "ior = 1.5 }",
        &format!("ior = {ior} }}"),
    )
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

/// The mean of `images` (one a seed) matches `scene`'s split tree (`right`
/// names it) in every channel of its well-conditioned pixels, more than
/// `min_stable` of all, and is told apart from `wrong`'s (named `wrong_name`).
fn assert_converges_to_split_tree(
    images: &[Image],
    (scene, right_name): (&Scene, &str),
    (wrong, wrong_name): (&Scene, &str),
    min_stable: f64,
) {
    let mean = Image::average(images);
    let cpu = cpu_expectation(scene);
    let (stable, pixels) = (cpu.2.iter().filter(|&&s| s).count(), cpu.2.len());
    let right = failing(&mean, images.len(), &cpu);
    let wrong = failing(&mean, images.len(), &cpu_expectation(wrong));
    eprintln!(
        "{stable} of {pixels} pixels well-conditioned; channels beyond 4.5 standard errors: {:.3}% against {right_name}, {:.3}% against {wrong_name}",
        100.0 * right,
        100.0 * wrong
    );
    assert!(
        stable as f64 > min_stable * pixels as f64,
        "too few pixels compared"
    );
    // At 4.5 sigma a correct estimator fails ~1e-5 of channels.
    assert!(
        right == 0.0,
        "GPU mean departs from {right_name} in {:.3}% of channels",
        100.0 * right
    );
    // A wrong expectation must show in a good part of the shape.
    assert!(
        wrong > 0.01,
        "{wrong_name} was not told apart ({:.3}%)",
        100.0 * wrong
    );
}

#[test]
fn stochastic_fresnel_choice_converges_to_the_split_tree() {
    let scene = glass_scene(1.5);
    let n = 256;
    let images = direct_renders(&scene, 1..n + 1);
    // The choice is really random: some pixels vary between seeds.
    assert!(
        images.iter().any(|im| im.pixels != images[0].pixels),
        "no pixel varies: nothing stochastic was tested"
    );
    // A different ior changes the expectation: the test must notice.
    // The ball fills about a tenth of the frame.
    assert_converges_to_split_tree(
        &images,
        (&scene, "the split tree"),
        (&glass_scene(1.6), "ior 1.6"),
        0.9,
    );
}

/// GLASS BALL's geometry under a point light with the ball a smooth metal
/// (`metal` of src/scene/metals.rs): every path is deterministic.
fn metal_scene(metal: &str) -> Scene {
    let text = common::replace_once(
        &common::fixture_text("glass_point"),
        "glass = { type = \"glass\", ior = 1.5 }",
        &format!("glass = {{ type = \"conductor\", metal = \"{metal}\" }}"),
    );
    load_scene_str(&text, &common::fixture_file("glass_point")).unwrap()
}

/// A smooth metal reflects by its exact complex Fresnel (the BSDF layer's
/// delta lobe): the GPU image meets the twin's expectation in every
/// well-conditioned pixel, and is told apart from another metal's.
#[test]
fn a_smooth_metal_reflects_by_its_fresnel() {
    let scene = metal_scene("Au");
    let images = direct_renders(&scene, 1..3);
    assert_converges_to_split_tree(
        &images,
        (&scene, "gold's Fresnel"),
        (&metal_scene("Cu"), "copper's"),
        0.9,
    );
}

/// A surface seen only through glass (a diffuse square and a point light
/// sealed in a glass ball) is dimmer by radiance's 1 / ior^2 where the eye
/// path enters: the GPU's mean over seeds meets the twin's split tree with
/// the factor, and is told apart from the same tree without it (the square's
/// albedo times ior^2 stands for it, as every path to the square enters the
/// ball once and leaves it never).
#[test]
fn a_surface_inside_glass_is_seen_dimmer_by_radiance_eta_squared() {
    let scene = common::fixture("glass_inside");
    let images = direct_renders(&scene, 1..129);
    let mut unscaled = scene.clone();
    let ior: f32 = 1.5;
    for m in unscaled.materials.iter_mut() {
        if let photonmap::scene::Material::Diffuse { albedo } = m {
            *albedo *= ior * ior;
        }
    }
    assert_converges_to_split_tree(
        &images,
        (&scene, "the split tree with (eta_i / eta_t)^2"),
        (&unscaled, "the tree without it"),
        0.8,
    );
}

#[test]
fn an_emitter_seen_directly_shows_its_radiance() {
    let gpu = common::gpu();
    let scene = common::paper_scene("cornell_box");
    let mut o = RenderOptions::for_scene(&scene).direct_only();
    (o.width, o.height) = (64, 64);
    let img = render(&gpu, &scene, &o, &mut ()).unwrap().image;
    let at_light = common::pixels_equal_to(&img, [25.0, 25.0, 25.0]);
    assert!(at_light >= 4, "{at_light} pixels show the light's Le = 25");
    // Nothing else is brighter than the light.
    assert!(img.pixels.iter().flatten().all(|&v| v <= 25.0));
}

#[test]
fn direct_light_from_a_point_light_matches_the_closed_form() {
    // A floor under a point light straight above the pixel seen at the image centre:
    // L = albedo / pi * I * cos / r^2 with cos = 1.
    let scene = common::fixture("point_over_floor");
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

/// `glass_scene` with its sphere as an OBJ UV sphere of about `triangles`
/// triangles with vertex normals (the sphere's own).
fn shaded_glass_scene(triangles: usize, ior: f32) -> Scene {
    let dir = common::TempDir::new("shaded_glass");
    common::write_sphere_obj(&dir.join("sphere.obj"), triangles, true);
    let text = glass_text(ior).replace(
        "type = \"sphere\"\ncenter = [0.0, 0.8, 0.0]\nradius = 0.8\nmaterial = \"glass\"",
        "type = \"mesh\"\nfile = \"sphere.obj\"\nscale = 0.8\ntranslate = [0.0, 0.8, 0.0]\nmaterial = \"glass\"",
    );
    load_scene_str(&text, &dir.join("shaded_glass.toml")).unwrap()
}

/// The eye side of shading normals against its twin: mirror and glass
/// directions about the interpolated normal, falling back to the geometric
/// one where they would leave on the wrong side, and the shading cosine in
/// direct light, on a coarse glass sphere (so interpolated and facet normals
/// differ much) under a point light.
#[test]
fn a_glass_mesh_with_vertex_normals_converges_to_its_split_tree() {
    let scene = shaded_glass_scene(224, 1.5);
    let images = direct_renders(&scene, 1..257);
    // The same sphere without its normals (flat facets) is another image.
    let mut flat = scene.clone();
    flat.shapes.iter_mut().for_each(|s| s.normals = None);
    assert_converges_to_split_tree(
        &images,
        (&scene, "the shaded split tree"),
        (&flat, "flat facets"),
        0.8,
    );
}

/// A floor and a diffuse sphere mesh with vertex normals, lit only by
/// emissive OBJ triangles in two groups: a quad and a small triangle of one
/// material (Ke 8 6 4 times `scale`), a tilted triangle of another.
fn triangle_lights_scene(scale: f32) -> Scene {
    let dir = common::TempDir::new(&format!("triangle_lights_{scale}"));
    common::write_sphere_obj(&dir.join("sphere.obj"), 224, true);
    let (w, c) = (
        Vec3::new(8.0, 6.0, 4.0) * scale,
        Vec3::new(2.0, 3.0, 5.0) * scale,
    );
    std::fs::write(
        dir.join("lamps.mtl"),
        format!(
            "newmtl warm\nKe {} {} {}\nnewmtl cold\nKe {} {} {}\n",
            w.x, w.y, w.z, c.x, c.y, c.z
        ),
    )
    .unwrap();
    std::fs::write(
        dir.join("lamps.obj"),
        "mtllib lamps.mtl\no a\nusemtl warm\nv -1 2 -1\nv 0 2 -1\nv 0 2 0\nv -1 2 0\nv 0.2 2 0.2\nv 0.5 2 0.2\nv 0.2 2 0.4\nf 1 2 3 4\nf 5 6 7\no b\nusemtl cold\nv 1 1.5 1\nv 2 1.8 1\nv 1 1.6 2\nf 8 9 10\n",
    )
    .unwrap();
    let text = r#"
[camera]
position = [0.0, 1.2, 4.5]
look_at = [0.0, 0.4, 0.0]
vfov = 40.0
width = 40
height = 32
[render]
shadow_rays = 4
[materials]
floor = { type = "diffuse", albedo = [0.7, 0.6, 0.5] }
clay = { type = "diffuse", albedo = [0.6, 0.6, 0.3] }
[[shape]]
type = "parallelogram"
corner = [-3.0, 0.0, -3.0]
edge1 = [0.0, 0.0, 6.0]
edge2 = [6.0, 0.0, 0.0]
material = "floor"
[[shape]]
type = "mesh"
file = "sphere.obj"
scale = 0.5
translate = [0.0, 0.5, 0.0]
material = "clay"
[[shape]]
type = "mesh"
file = "lamps.obj"
"#;
    let scene = load_scene_str(text, &dir.join("lamps.toml")).unwrap();
    assert_eq!(scene.lights.len(), 2);
    scene
}

fn direct_renders(scene: &Scene, seeds: std::ops::Range<u32>) -> Vec<Image> {
    let gpu = common::gpu();
    seeds
        .map(|seed| {
            let mut o = RenderOptions::for_scene(scene).direct_only();
            o.seed = seed;
            render(&gpu, scene, &o, &mut ()).unwrap().image
        })
        .collect()
}

/// The twin of the direct-light pass, fed the same random numbers, pixel by
/// pixel: which triangle each shadow sample picks, where it lands in it,
/// the shading normal's cosine. Pixels may differ only where f32 rounding
/// flips a shadow ray at an edge.
#[test]
fn direct_light_from_emissive_triangles_equals_its_twin_sample_for_sample() {
    use photonmap::scene::pack::PackedScene;
    use photonmap::twins::ray_trace::direct_light_sampled;
    let scene = triangle_lights_scene(1.0);
    let packed = PackedScene::new(&scene);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let (mut differ, mut lit) = (0, 0);
    for (k, img) in direct_renders(&scene, 7..9).iter().enumerate() {
        for y in 0..h {
            for x in 0..w {
                let ray = eye_ray_at(&scene, w, h, x as f32 + 0.5, y as f32 + 0.5);
                let twin =
                    direct_light_sampled(&scene, &packed, 7 + k as u32, [x, h - 1 - y], 4, ray);
                let gpu = Vec3::from(img.get(x, y));
                lit += usize::from(twin.max_element() > 0.0);
                if (gpu - twin).abs().max_element() > 1e-4 * twin.max_element() + 1e-7 {
                    differ += 1;
                }
            }
        }
    }
    let pixels = 2 * w * h;
    eprintln!("{differ} of {pixels} pixels differ from the twin beyond 1e-4 ({lit} lit)");
    assert!(
        lit as f64 > 0.5 * pixels as f64,
        "too few lit pixels ({lit})"
    );
    assert!(
        differ as f64 <= 0.005 * pixels as f64,
        "{differ} of {pixels} pixels differ"
    );
}

/// Direct light from the same triangles against the twin's quadrature (a
/// 32 x 32 midpoint rule on each triangle, through the map that makes it
/// uniform in area): block by block (4 x 4 pixels), the GPU's mean over 64
/// seeds must lie within 4.5 standard errors, measured from the seeds'
/// spread, plus the quadrature's own error (32 against 64 points a side).
/// Blocks, not pixels: a pixel whose light is a rare event (a small
/// triangle seen through a narrow gap) may show none in 64 seeds, so its
/// seeds' spread says nothing of its error.
#[test]
fn direct_light_from_emissive_triangles_converges_to_the_twin_quadrature() {
    use photonmap::twins::ray_trace::expected_radiance;
    let (scene, brighter) = (triangle_lights_scene(1.0), triangle_lights_scene(1.1));
    let n = 64;
    let images = direct_renders(&scene, 1..n + 1);
    let (w, h) = (scene.camera.width, scene.camera.height);
    let expect = |s: &Scene, grid: u32, dx: f32, dy: f32| -> Vec<f64> {
        (0..w * h)
            .map(|i| {
                let (x, y) = ((i % w) as f32 + 0.5 + dx, (i / w) as f32 + 0.5 + dy);
                let (o, d) = eye_ray_at(s, w, h, x, y);
                expected_radiance(s, o, d, 0, grid).element_sum() as f64 / 3.0
            })
            .collect()
    };
    let (e32, e64, wrong) = (
        expect(&scene, 32, 0.0, 0.0),
        expect(&scene, 64, 0.0, 0.0),
        expect(&brighter, 32, 0.0, 0.0),
    );
    // As in `cpu_expectation`: pixels whose expectation moves when the eye
    // ray moves by 1/100 pixel (silhouettes, where f32 rounding in GLSL and
    // Rust may hit different triangles) leave their block out.
    let moved: Vec<Vec<f64>> = [(0.01, 0.0), (-0.01, 0.0), (0.0, 0.01), (0.0, -0.01)]
        .iter()
        .map(|&(dx, dy)| expect(&scene, 8, dx, dy))
        .collect();
    let e8 = expect(&scene, 8, 0.0, 0.0);
    let stable = |i: usize| {
        moved
            .iter()
            .all(|m| (m[i] - e8[i]).abs() <= 0.05 * e8[i] + 1e-4)
    };
    let lum = |img: &Image, i: usize| img.pixels[i].iter().map(|&v| v as f64).sum::<f64>() / 3.0;
    let (mut compared, mut chi2, mut beyond, mut beyond_wrong) = (0, 0.0, 0, 0);
    for by in 0..h / 4 {
        for bx in 0..w / 4 {
            let pixels: Vec<usize> = (0..16)
                .map(|k| ((by * 4 + k / 4) * w + bx * 4 + k % 4) as usize)
                .collect();
            if !pixels.iter().all(|&i| stable(i)) {
                continue;
            }
            let block = |f: &dyn Fn(usize) -> f64| pixels.iter().map(|&i| f(i)).sum::<f64>() / 16.0;
            let per_seed: Vec<f64> = images.iter().map(|img| block(&|i| lum(img, i))).collect();
            let m = per_seed.iter().sum::<f64>() / n as f64;
            let var = per_seed.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1) as f64;
            let quadrature = block(&|i| e32[i] - e64[i]).abs();
            let (e, e_wrong) = (block(&|i| e32[i]), block(&|i| wrong[i]));
            let se = (var / n as f64 + quadrature * quadrature + (1e-3 * e).powi(2) + 1e-12).sqrt();
            let z = (m - e) / se;
            compared += 1;
            chi2 += z * z;
            beyond += usize::from(z.abs() > 4.5);
            beyond_wrong += usize::from(((m - e_wrong) / se).abs() > 4.5);
        }
    }
    eprintln!(
        "{compared} of {} blocks compared: chi^2/n = {:.2}, {beyond} beyond 4.5 standard errors; against a 10% brighter light {beyond_wrong}",
        (w / 4) * (h / 4),
        chi2 / compared as f64
    );
    assert!(
        compared as u32 > (w / 4) * (h / 4) / 2,
        "too few blocks compared"
    );
    assert_eq!(beyond, 0, "blocks depart from the twin's quadrature");
    assert!(
        beyond_wrong * 4 > compared,
        "a 10% brighter light was not told apart"
    );
}
