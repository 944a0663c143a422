//! OBJ meshes through the real GL pipeline: a tessellated glass sphere with
//! vertex normals renders GLASS BALL as the analytic sphere does, an
//! emissive OBJ quad lights a scene as the equivalent area light does
//! (direct light, the photon map, SPPM), and the measured Cornell box
//! renders. "As" means within the two renders' noise, measured from their
//! seed-to-seed spread (`common::block_chi2`); each comparison also shows
//! it tells a wrong scene apart.

use crate::common;

use std::path::Path;

use photonmap::render::sppm::{render_sppm, DirectLighting, SppmOptions};
use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::{load_scene_str, Light, Scene};

const SEEDS: u32 = 8;

/// `SEEDS` renders from seed `first` on: each scene of a comparison takes
/// seeds of its own, so that the two are independent.
fn renders(scene: &Scene, w: u32, h: u32, direct_only: bool, first: u32) -> Vec<Image> {
    let gpu = common::gpu();
    (0..SEEDS)
        .map(|seed| {
            let mut o = RenderOptions::for_scene(scene);
            if direct_only {
                o = o.direct_only();
            }
            (o.width, o.height, o.seed) = (w, h, first + seed);
            render(&gpu, scene, &o, &mut ()).unwrap().image
        })
        .collect()
}

/// Asserts that A and B agree and that A and `wrong` do not, printing the
/// measured statistics.
fn agree(what: &str, a: &[Image], b: &[Image], wrong: &[Image], block: u32) {
    let (chi2, blocks, bound) = common::block_chi2(a, b, block);
    let (chi2_wrong, _, _) = common::block_chi2(a, wrong, block);
    eprintln!(
        "{what}: chi^2/n = {chi2:.2} over {blocks} blocks (bound {bound:.2}); against the wrong scene {chi2_wrong:.1}"
    );
    assert!(chi2 <= bound, "{what}: chi^2/n = {chi2} > {bound}");
    assert!(
        chi2_wrong > bound,
        "{what}: the wrong scene was not told apart ({chi2_wrong})"
    );
}

// ---- an emissive OBJ quad against the equivalent area light ------------------------

/// The area light of scenes/tests/stage.toml, 0.8 x 0.6 at y = 2.2 (out of
/// the camera's view), facing down.
const STAGE_LIGHT: &str = "[[light]]\ntype = \"area\"\ncorner = [-0.6, 2.2, -0.4]\nedge1 = [0.8, 0.0, 0.0]\nedge2 = [0.0, 0.0, 0.6]\nnormal = [0.0, -1.0, 0.0]\nradiance = [12.0, 12.0, 12.0]\n";

/// The stage lit by its area light, or by the same rectangle as an emissive
/// OBJ quad of radiance `ke`.
fn lit_stage(obj_light: Option<f32>) -> Scene {
    let Some(ke) = obj_light else {
        return common::fixture("stage");
    };
    let dir = common::TempDir::new("lit_stage");
    let name = format!("lamp_{ke}");
    std::fs::write(
        dir.join(format!("{name}.mtl")),
        format!("newmtl lamp\nKe {ke} {ke} {ke}\n"),
    )
    .unwrap();
    // Counter-clockwise seen from below: its front faces down.
    std::fs::write(
        dir.join(format!("{name}.obj")),
        format!("mtllib {name}.mtl\no lamp\nusemtl lamp\nv -0.6 2.2 -0.4\nv 0.2 2.2 -0.4\nv 0.2 2.2 0.2\nv -0.6 2.2 0.2\nf 1 2 3 4\n"),
    )
    .unwrap();
    let quad = format!("[[shape]]\ntype = \"mesh\"\nfile = \"{name}.obj\"\n");
    let text = common::replace_once(&common::fixture_text("stage"), STAGE_LIGHT, &quad);
    load_scene_str(&text, &dir.join("stage.toml")).unwrap()
}

fn sppm_renders(scene: &Scene, first: u32) -> Vec<Image> {
    let gpu = common::gpu();
    let sppm = SppmOptions {
        iterations: 16,
        photons_per_iteration: 1 << 13,
        direct: DirectLighting::Photons,
        ..SppmOptions::default()
    };
    (0..SEEDS)
        .map(|seed| {
            let mut o = RenderOptions::for_scene(scene);
            (o.width, o.height, o.seed) = (32, 24, first + seed);
            render_sppm(&gpu, scene, &o, &sppm, &mut ()).unwrap().image
        })
        .collect()
}

#[test]
fn an_emissive_obj_quad_lights_like_the_equivalent_area_light() {
    let area = lit_stage(None);
    let quad = lit_stage(Some(12.0));
    let brighter = lit_stage(Some(12.0 * 1.1));
    assert!(matches!(
        quad.lights[..],
        [Light::Triangles { count: 2, .. }]
    ));
    let (pa, pq) = (
        area.lights[0].power(&area.shapes),
        quad.lights[0].power(&quad.shapes),
    );
    assert!(
        (pa - pq).abs().max_element() < 1e-5 * pa.max_element(),
        "{pa} {pq}"
    );
    // Direct light by shadow rays; then with indirect light from the photon map.
    for (what, direct_only) in [("direct light", true), ("photon map", false)] {
        let frame = |s: &Scene, first| renders(s, 48, 36, direct_only, first);
        agree(
            what,
            &frame(&area, 100),
            &frame(&quad, 200),
            &frame(&brighter, 300),
            4,
        );
    }
    // SPPM with photons carrying direct light too: emission alone lights it.
    agree(
        "SPPM (photons only)",
        &sppm_renders(&area, 100),
        &sppm_renders(&quad, 200),
        &sppm_renders(&brighter, 300),
        4,
    );
}

/// The stage under its area light with its ball as an OBJ sphere of 20,000
/// triangles with vertex normals, of albedo `albedo` x the analytic ball's.
fn stage_with_mesh_ball(albedo: f32) -> Scene {
    let dir = common::TempDir::new("stage_mesh_ball");
    common::write_sphere_obj(&dir.join("ball.obj"), 20_000, true);
    let ball = "type = \"sphere\"\ncenter = [0.3, 0.5, 0.0]\nradius = 0.5\nmaterial = \"ball\"";
    let mesh = "type = \"mesh\"\nfile = \"ball.obj\"\nscale = 0.5\ntranslate = [0.3, 0.5, 0.0]\nmaterial = \"ball\"";
    let [r, g, b] = [0.3f32, 0.5, 0.7].map(|c| c * albedo);
    let text = common::replace_once(&common::fixture_text("stage"), ball, mesh);
    let text = common::replace_once(
        &text,
        "ball = { type = \"diffuse\", albedo = [0.3, 0.5, 0.7] }",
        &format!("ball = {{ type = \"diffuse\", albedo = [{r:?}, {g:?}, {b:?}] }}"),
    );
    load_scene_str(&text, &dir.join("stage.toml")).unwrap()
}

/// Shading normals are consistent between the eye and the photons: a
/// diffuse ball as a fine OBJ sphere with vertex normals (shaded by the
/// interpolated normal, its photons weighted by the adjoint's correction)
/// renders the stage, direct light and photon map, as the analytic ball does.
#[test]
fn a_diffuse_obj_sphere_with_vertex_normals_matches_the_analytic_ball() {
    let analytic = lit_stage(None);
    let mesh = stage_with_mesh_ball(1.0);
    assert!(mesh.shapes.iter().filter(|s| s.normals.is_some()).count() > 19_000);
    agree(
        "diffuse ball, analytic against a 20k-triangle OBJ sphere",
        &renders(&analytic, 48, 36, false, 100),
        &renders(&mesh, 48, 36, false, 200),
        &renders(&stage_with_mesh_ball(0.8), 48, 36, false, 300),
        4,
    );
}

// ---- GLASS BALL with a tessellated OBJ sphere -----------------------------------------

/// GLASS BALL with its sphere as an OBJ UV sphere of about `triangles`
/// triangles (vertex normals: the exact sphere's), glass of `ior`.
fn glass_ball_mesh(triangles: usize, ior: f32) -> Scene {
    let dir = common::TempDir::new("glass_ball_mesh");
    common::write_sphere_obj(&dir.join("sphere.obj"), triangles, true);
    let text = std::fs::read_to_string(common::scene_file("glass_ball")).unwrap();
    let sphere = "type = \"sphere\"\ncenter = [0.0, 0.8, 0.0]\nradius = 0.8\nmaterial = \"glass\"";
    assert!(text.contains(sphere));
    let mesh = "type = \"mesh\"\nfile = \"sphere.obj\"\nscale = 0.8\ntranslate = [0.0, 0.8, 0.0]\nmaterial = \"glass\"";
    let text = text.replace(sphere, mesh).replace(
        "glass = { type = \"glass\", ior = 1.5 }",
        &format!("glass = {{ type = \"glass\", ior = {ior:?} }}"),
    );
    load_scene_str(&text, &dir.join("glass_ball_mesh.toml")).unwrap()
}

#[test]
fn glass_ball_with_a_tessellated_obj_sphere_matches_the_analytic_one() {
    let analytic = common::paper_scene("glass_ball");
    let mesh = glass_ball_mesh(20_000, 1.5);
    assert!(
        mesh.shapes.len() > 19_000
            && mesh.shapes.iter().all(|s| s.normals.is_some()
                || s.material == 0
                || matches!(s.geometry, photonmap::scene::Geometry::Parallelogram { .. }))
    );
    let (w, h) = (128, 96);
    let a = renders(&analytic, w, h, false, 100);
    let b = renders(&mesh, w, h, false, 200);
    let wrong = renders(&glass_ball_mesh(20_000, 1.6), w, h, false, 300);
    agree(
        "GLASS BALL, analytic against a 20k-triangle OBJ sphere",
        &a,
        &b,
        &wrong,
        8,
    );
}

#[test]
fn the_measured_cornell_box_renders() {
    let scene = common::paper_scene("cornell_box_obj");
    let gpu = common::gpu();
    let mut o = RenderOptions::for_scene(&scene);
    (o.width, o.height) = (64, 64);
    let img = render(&gpu, &scene, &o, &mut ()).unwrap().image;
    assert!(img
        .pixels
        .iter()
        .flatten()
        .all(|v| v.is_finite() && *v >= 0.0));
    // The light, seen from below, shows its Ke.
    let lit = common::pixels_equal_to(&img, [17.0, 12.0, 4.0]);
    assert!(lit >= 4, "{lit} pixels show Ke");
    // Red wall left, green wall right, at mid height.
    let (left, right) = (img.get(4, 32), img.get(59, 32));
    assert!(
        left[0] > 2.0 * left[1] && right[1] > 2.0 * right[0],
        "{left:?} {right:?}"
    );
    let _ = Path::new("");
}
