//! The stress suite (`photonmap bench stress`): each case reports a figure and
//! an outcome (pass, fail, or refused with a clear message), and every render
//! is checked for NaN or Inf in every GPU buffer it leaves.

use glam::{DVec3, Vec3};

use crate::error::{Error, Result};
use crate::gpu::{Gpu, TexFormat, Texture};
use crate::metrics::compare;
use crate::photon::{BitonicBuild, BuildMethod, PhotonConfig, PhotonMap};
use crate::render::{render, Method, PhotonMapOptions, RenderOptions, RenderOutput};
use crate::scene::{embedded, load_scene_str, load_scene_str_translated, Light, Rebase, Scene};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    Pass,
    Fail,
    Refused,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct StressCase {
    pub name: String,
    /// What `value` measures.
    pub figure: String,
    pub value: f64,
    pub outcome: Outcome,
    pub message: String,
    pub seconds: f64,
}

/// Non-finite values in every buffer a render leaves (direct light, hit
/// records, the photon map, the estimate's state, the image): "" if none.
pub fn non_finite_buffers(out: &RenderOutput) -> String {
    let mut bad = Vec::new();
    let mut check = |name: &str, t: &Texture| {
        if t.is_integer() {
            return;
        }
        let n = t.read_f32().iter().filter(|v| !v.is_finite()).count();
        if n > 0 {
            bad.push(format!("{name}: {n}"));
        }
    };
    let d = &out.state.direct;
    check("direct radiance", &d.radiance);
    check("diffuse positions", &d.diffuse_position);
    check("diffuse normals", &d.diffuse_normal);
    check("diffuse throughput", &d.diffuse_throughput);
    match out.map() {
        Some(PhotonMap::Sorted(m)) => {
            check("map positions", &m.position);
            check("map power", &m.power);
        }
        Some(PhotonMap::Routed(m)) => {
            check("map positions", &m.position);
            check("map power", &m.power);
            check("map counts", &m.counts);
        }
        None => {}
    }
    if let Some(e) = out.radiance_estimate() {
        check("estimate flux", &e.flux);
    }
    if out.image.has_non_finite() {
        bad.push("image".into());
    }
    bad.join(", ")
}

/// The scene scaled by `s` about the origin and then moved by `t`: lengths,
/// the photon-map radius and grid bounds scale; point-light intensity scales by
/// s^2 so irradiance (I / r^2) and so the image stay the same.
pub fn transformed(scene: &Scene, s: f32, t: Vec3) -> Scene {
    let p = |v: Vec3| v * s + t;
    let mut out = scene.clone();
    out.camera.position = p(scene.camera.position);
    out.camera.look_at = p(scene.camera.look_at);
    for shape in &mut out.shapes {
        shape.geometry = shape.geometry.scaled(s, p);
    }
    for light in &mut out.lights {
        match light {
            Light::Area {
                corner,
                edge1,
                edge2,
                ..
            } => {
                *corner = p(*corner);
                *edge1 *= s;
                *edge2 *= s;
            }
            Light::Point {
                position,
                intensity,
            } => {
                *position = p(*position);
                *intensity = *intensity * s * s;
            }
            // Its triangles are shapes, moved above.
            Light::Triangles { .. } => {}
        }
    }
    out.photon_map.max_radius *= s;
    out.photon_map.grid_bounds = scene.photon_map.grid_bounds.map(|(lo, hi)| (p(lo), p(hi)));
    out
}

fn small(scene: &Scene, w: u32, h: u32, seed: u32) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (w, h, seed);
    o
}

fn case(
    name: &str,
    figure: &str,
    f: impl FnOnce() -> Result<(f64, Outcome, String)>,
) -> StressCase {
    let t0 = std::time::Instant::now();
    let (value, outcome, message) = match f() {
        Ok(r) => r,
        // An error is a refusal when it explains itself; every Error does.
        Err(e) => (f64::NAN, Outcome::Refused, e.to_string()),
    };
    StressCase {
        name: name.into(),
        figure: figure.into(),
        value,
        outcome,
        message,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

fn finite_render(gpu: &Gpu, scene: &Scene, o: &RenderOptions) -> Result<(RenderOutput, String)> {
    let out = render(gpu, scene, o, &mut ())?;
    let bad = non_finite_buffers(&out);
    Ok((out, bad))
}

fn verdict(ok: bool, bad: &str, detail: String) -> (Outcome, String) {
    if !bad.is_empty() {
        (Outcome::Fail, format!("non-finite values in {bad}"))
    } else if ok {
        (Outcome::Pass, detail)
    } else {
        (Outcome::Fail, detail)
    }
}

/// A closed diffuse sphere of albedo rho and radius R lit by a point light of
/// intensity I at its centre: every wall point has L = rho I / (pi R^2 (1 - rho))
/// (direct rho I / (pi R^2) by shadow rays, the rest by photons). The embedded
/// scene scenes/tests/furnace.toml, which tests read as well.
const FURNACE: &str = "tests/furnace";

/// The text of the embedded scene `name`, or an error naming its file.
fn embedded_text(name: &str) -> Result<&'static str> {
    embedded::source(name).ok_or_else(|| {
        Error::from(crate::error::SceneError {
            file: format!("scenes/{name}.toml").into(),
            line: 0,
            field: "(file)".into(),
            message: "no embedded source".into(),
        })
    })
}

pub fn furnace(gpu: &Gpu) -> Result<(f64, f64, f64, String)> {
    let scene = embedded::load(FURNACE)?;
    let (out, bad) = finite_render(gpu, &scene, &small(&scene, 48, 48, 3))?;
    let mean = out.image.mean()[0];
    let (rho, k) = (0.5f64, scene.photon_map.k as f64);
    let expected = rho / (std::f64::consts::PI * (1.0 - rho));
    // Indirect is rho of the total; each estimate has relative error 1/sqrt(k),
    // over ~ (viewed area / disc area) independent discs; plus the k/(k-1) bias
    // of a k-nearest estimate and rho^24 of truncation.
    let density = scene.photon_map.photons_stored as f64 / (4.0 * std::f64::consts::PI);
    let disc = k / density;
    let viewed = 2.0 * std::f64::consts::PI * (1.0 - (60f64.to_radians() / 2.0).cos()) * 1.5 * 1.5;
    let sigma = rho * expected / k.sqrt() / (viewed / disc).max(1.0).sqrt();
    let tolerance = 4.0 * sigma + rho * expected / (k - 1.0) + expected * rho.powi(24);
    Ok((mean, expected, tolerance, bad))
}

/// Runs the stress cases; `quick` keeps those that take seconds. The scenes
/// are the embedded ones, so the suite runs from any folder; a case that
/// cannot run is a failure, never a skip.
pub fn run(gpu: &Gpu, quick: bool, progress: &dyn Fn(&str)) -> Vec<StressCase> {
    let mut cases = Vec::new();
    scale_and_place(gpu, quick, progress, &mut cases);
    sizes(gpu, quick, progress, &mut cases);
    grids(gpu, quick, progress, &mut cases);
    bad_input(gpu, &mut cases);
    difficult_paths(gpu, &mut cases);
    meshes(gpu, progress, &mut cases);
    if !quick {
        progressive(gpu, progress, &mut cases);
    }
    progress("furnace");
    cases.push(case(
        "furnace: closed diffuse sphere, point light at its centre",
        "mean radiance (expected rho I / (pi R^2 (1 - rho)))",
        || {
            let (mean, expected, tolerance, bad) = furnace(gpu)?;
            let (o, m) = verdict(
                (mean - expected).abs() <= tolerance,
                &bad,
                format!("expected {expected:.5} +- {tolerance:.5}"),
            );
            Ok((mean, o, m))
        },
    ));
    cases
}

/// A case that could not run at all: a failure, with why.
fn could_not_run(name: &str, figure: &str, e: &Error) -> StressCase {
    StressCase {
        name: name.into(),
        figure: figure.into(),
        value: f64::NAN,
        outcome: Outcome::Fail,
        message: format!("could not run: {e}"),
        seconds: 0.0,
    }
}

/// How a stress case places a paper scene.
#[derive(Clone, Copy)]
enum Placement {
    /// The loaded scene scaled about the origin (`transformed`, in f32:
    /// scale is relative precision, which f32 keeps at any scale).
    Scaled(f32),
    /// The scene's file moved by this much along (1, -1, 1): read in f64,
    /// moved, and rebased as said (`load_scene_str_translated`).
    Moved(f64, Rebase),
}

/// The placements of one scene: four scales; three moves (two when quick),
/// rebased to the scene's centre; and for RING, moved by 1e6, rebased to its
/// camera as well, to compare the two choices of local origin.
fn placements(name: &str, quick: bool) -> Vec<(String, Placement)> {
    let scales: &[(&str, f32)] = &[("1e-4", 1e-4), ("1e-3", 1e-3), ("1e3", 1e3), ("1e4", 1e4)];
    let moves: &[(&str, f64)] = if quick {
        &[("1e4", 1e4), ("1e6", 1e6)]
    } else {
        &[("1e4", 1e4), ("1e6", 1e6), ("1e8", 1e8)]
    };
    let mut out: Vec<_> = scales
        .iter()
        .map(|&(label, s)| (format!("scaled by {label}"), Placement::Scaled(s)))
        .collect();
    for &(label, t) in moves {
        let placement = Placement::Moved(t, Rebase::SceneCentre);
        out.push((format!("moved by {label}"), placement));
        if name == "ring" && t == 1e6 {
            let placement = Placement::Moved(t, Rebase::Camera);
            out.push((
                format!("moved by {label}, rebased to its camera"),
                placement,
            ));
        }
    }
    out
}

/// Why a scene of this size moved by `t` is beyond what its file can hold,
/// if it is: f64's spacing at the moved coordinates coarser than f32's at
/// the scene's own size, which is what the rebased f32 scene resolves.
fn beyond_f64(size: f64, t: DVec3) -> Option<String> {
    let far = t.abs().max_element() + size;
    let f64_step = far * f64::EPSILON;
    let f32_step = size * f64::from(f32::EPSILON);
    (f64_step > f32_step).then(|| {
        format!(
            "coordinates of {far:.1e} are resolved by f64 only to {f64_step:.1e}, coarser than the {f32_step:.1e} f32 resolves at the scene's size {size:.2}: no file in f64 holds this scene so far out"
        )
    })
}

/// The scene `name` placed as said.
fn placed(name: &str, scene: &Scene, placement: Placement) -> Result<Scene> {
    match placement {
        Placement::Scaled(s) => Ok(transformed(scene, s, Vec3::ZERO)),
        Placement::Moved(d, rebase) => {
            let text = embedded_text(name)?;
            let file = format!("scenes/{name}.toml");
            let t = DVec3::new(d, -d, d);
            Ok(load_scene_str_translated(
                text,
                std::path::Path::new(&file),
                t,
                rebase,
            )?)
        }
    }
}

/// Scale and place: each paper scene (GLASS BALL when quick) scaled by 1e-4
/// to 1e4 and its file moved by 1e4 to 1e8 renders within twice the
/// seed-to-seed relative MSE of the original, or is refused where f64
/// cannot hold the moved file.
fn scale_and_place(gpu: &Gpu, quick: bool, progress: &dyn Fn(&str), cases: &mut Vec<StressCase>) {
    let scenes: &[&str] = if quick {
        &["glass_ball"]
    } else {
        &embedded::PAPER_SCENES
    };
    let figure = "relative MSE against the original (limit: 2 x seed-to-seed)";
    let (w, h) = (64, 48);
    for name in scenes {
        let placements = placements(name, quick);
        let baseline = (|| -> Result<_> {
            let scene = embedded::load(name)?;
            let base = render(gpu, &scene, &small(&scene, w, h, 1), &mut ())?;
            let other_seed = render(gpu, &scene, &small(&scene, w, h, 2), &mut ())?;
            let noise = compare(&other_seed.image, &base.image, None)?.rel_mse;
            Ok((scene, base.image, noise))
        })();
        let (scene, base, noise) = match baseline {
            Ok(b) => b,
            Err(e) => {
                for (label, _) in placements {
                    cases.push(could_not_run(&format!("{name} {label}"), figure, &e));
                }
                continue;
            }
        };
        for (label, placement) in placements {
            progress(&format!("{name} {label}"));
            cases.push(case(&format!("{name} {label}"), figure, || {
                if let Placement::Moved(d, _) = placement {
                    let size = f64::from(scene.size());
                    if let Some(why) = beyond_f64(size, DVec3::new(d, -d, d)) {
                        return Ok((f64::NAN, Outcome::Refused, why));
                    }
                }
                let moved = placed(name, &scene, placement)?;
                let (out, bad) = finite_render(gpu, &moved, &small(&moved, w, h, 1))?;
                let e = compare(&out.image, &base, None)?.rel_mse;
                let mut detail = format!("seed-to-seed {noise:.5}");
                if let Placement::Moved(..) = placement {
                    let o = moved.origin.to_array();
                    detail += &format!("; local origin {o:?}");
                }
                let (o, m) = verdict(e <= 2.0 * noise, &bad, detail);
                Ok((e, o, m))
            }));
        }
    }
}

/// Size: sorting stays exact up to the largest sizes; float addressing
/// refuses what it cannot address.
fn sizes(gpu: &Gpu, quick: bool, progress: &dyn Fn(&str), cases: &mut Vec<StressCase>) {
    let sizes: &[u32] = if quick { &[18] } else { &[22, 24] };
    for &k in sizes {
        progress(&format!("sort 2^{k}"));
        cases.push(case(
            &format!("bitonic sort of 2^{k} pairs"),
            "pairs out of order against a CPU sort",
            || {
                let wrong = sort_errors(gpu, 1usize << k)?;
                let outcome = if wrong == 0 {
                    Outcome::Pass
                } else {
                    Outcome::Fail
                };
                Ok((wrong as f64, outcome, String::new()))
            },
        ));
    }
    cases.push(case(
        "--faithful float addressing past 2^24",
        "texels",
        || {
            let tex = Texture::new(gpu, 8192, 4096, TexFormat::Rg32I)?;
            match BitonicBuild::with_addressing(gpu, true)?.sort(tex) {
                Err(e) => Ok(((1u64 << 25) as f64, Outcome::Refused, e.to_string())),
                Ok(_) => Ok((
                    (1u64 << 25) as f64,
                    Outcome::Fail,
                    "sorted past 2^24 with float addresses".into(),
                )),
            }
        },
    ));
}

/// Pairs out of order after a GPU bitonic sort of n random keys, against a CPU sort.
fn sort_errors(gpu: &Gpu, n: usize) -> Result<usize> {
    let (w, h) = crate::photon::compaction::sort_texture_size(n as u64);
    let keys: Vec<i32> = (0..n as u32)
        .map(|i| (crate::random::pcg_hash(99u32.wrapping_add(i + 1)) % 100_000) as i32)
        .collect();
    let data = crate::photon::bitonic::key_records(&keys);
    let tex = Texture::from_texels(gpu, w, h, TexFormat::Rg32I, &data)?;
    let (sorted, _) = BitonicBuild::new(gpu)?.sort(tex)?;
    let got = sorted.read_i32();
    Ok(crate::photon::bitonic::sorted_pairs(&keys)
        .iter()
        .enumerate()
        .filter(|(i, p)| got[2 * i] != p.0 || got[2 * i + 1] != p.1)
        .count())
}

/// Grids and search edges, on GLASS BALL at a small size.
fn grids(gpu: &Gpu, quick: bool, progress: &dyn Fn(&str), cases: &mut Vec<StressCase>) {
    let figure = "mean image radiance";
    let glass = match embedded::load("glass_ball") {
        Ok(s) => s,
        Err(e) => {
            cases.push(could_not_run("grids and search edges", figure, &e.into()));
            return;
        }
    };
    let with = |f: &dyn Fn(&mut Scene)| {
        let mut g = glass.clone();
        f(&mut g);
        g
    };
    let one_cell = with(&|g| g.photon_map.grid_resolution = [1, 1, 1]);
    let mut grid_cases: Vec<(String, Scene, BuildMethod)> = vec![
        (
            "grid 1 x 1 x 1, all photons in one cell (bitonic)".into(),
            one_cell.clone(),
            BuildMethod::Bitonic,
        ),
        (
            "grid 1 x 1 x 1, all photons in one cell (stencil, 16 of 5000 kept)".into(),
            one_cell,
            BuildMethod::Stencil,
        ),
    ];
    if !quick {
        let huge = with(&|g| g.photon_map.grid_resolution = [512, 512, 512]);
        grid_cases.push((
            "grid 512^3 (stencil routing)".into(),
            huge.clone(),
            BuildMethod::Stencil,
        ));
        grid_cases.push(("grid 512^3 (bitonic)".into(), huge, BuildMethod::Bitonic));
    }
    grid_cases.push((
        "grid bounds that miss every photon".into(),
        with(&|g| {
            g.photon_map.grid_bounds =
                Some((Vec3::new(10.0, 10.0, 10.0), Vec3::new(11.0, 11.0, 11.0)))
        }),
        BuildMethod::Bitonic,
    ));
    grid_cases.push((
        "k = 4096 with 1000 photons".into(),
        with(&|g| {
            g.photon_map.k = 4096;
            g.photon_map.photons_stored = 1000;
        }),
        BuildMethod::Bitonic,
    ));
    for (label, scene, build) in grid_cases {
        progress(&label);
        cases.push(case(&label, figure, || {
            let mut o = small(&scene, 64, 48, 1);
            o.method = Method::PhotonMap(PhotonMapOptions {
                photons: PhotonConfig {
                    build,
                    ..PhotonConfig::default()
                },
                ..PhotonMapOptions::default()
            });
            let (out, bad) = finite_render(gpu, &scene, &o)?;
            let mean = out.image.mean()[0];
            let (o, m) = verdict(true, &bad, String::new());
            Ok((mean, o, m))
        }));
    }
}

/// Bad input is refused with a clear message, and an empty map too.
fn bad_input(gpu: &Gpu, cases: &mut Vec<StressCase>) {
    let glass = embedded::source("glass_ball").unwrap_or_default();
    for (label, (from, to)) in [
        (
            "maximum radius zero",
            ("max_radius = 0.25", "max_radius = 0.0"),
        ),
        (
            "zero-area light",
            ("edge2 = [0.0, 0.0, 0.6]", "edge2 = [0.0, 0.0, 0.0]"),
        ),
        (
            "NaN in a position",
            ("center = [0.0, 0.8, 0.0]", "center = [0.0, nan, 0.0]"),
        ),
    ] {
        cases.push(case(label, "-", || {
            if !glass.contains(from) {
                return Ok((
                    f64::NAN,
                    Outcome::Fail,
                    format!("could not run: {from:?} is not in scenes/glass_ball.toml"),
                ));
            }
            match load_scene_str(
                &glass.replace(from, to),
                std::path::Path::new("scenes/glass_ball.toml"),
            ) {
                Err(e) => Ok((f64::NAN, Outcome::Refused, e.to_string())),
                Ok(_) => Ok((f64::NAN, Outcome::Fail, "accepted".into())),
            }
        }));
    }
    cases.push(case(
        "an empty photon map (no diffuse surface)",
        "-",
        || {
            let text = embedded_text(FURNACE)?.replace(
                "type = \"diffuse\", albedo = [0.5, 0.5, 0.5]",
                "type = \"mirror\", reflectance = [0.5, 0.5, 0.5]",
            );
            let scene = load_scene_str(&text, std::path::Path::new("mirror_sphere.toml"))?;
            match render(gpu, &scene, &small(&scene, 32, 32, 1), &mut ()) {
                Err(e) => Ok((0.0, Outcome::Refused, e.to_string())),
                Ok(o) => Ok((
                    o.image.mean()[0],
                    Outcome::Fail,
                    "rendered without photons".into(),
                )),
            }
        },
    ));
}

/// Paths: photons trapped in glass, coincident surfaces, grazing views.
fn difficult_paths(gpu: &Gpu, cases: &mut Vec<StressCase>) {
    let figure = "mean image radiance";
    cases.push(case(
        "glass of ior 9 (total internal reflection, trapped photons), coincident surfaces",
        figure,
        || {
            let trapped = embedded_text(FURNACE)?.replace("type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }", "type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }\nglass = { type = \"glass\", ior = 9.0 }")
        + "[[shape]]\ntype = \"sphere\"\ncenter = [0.3, 0.0, -0.4]\nradius = 0.25\nmaterial = \"glass\"\n[[shape]]\ntype = \"parallelogram\"\ncorner = [-0.5, -0.5, -0.6]\nedge1 = [1.0, 0.0, 0.0]\nedge2 = [0.0, 1.0, 0.0]\nmaterial = \"wall\"\n[[shape]]\ntype = \"parallelogram\"\ncorner = [-0.5, -0.5, -0.6]\nedge1 = [0.0, 1.0, 0.0]\nedge2 = [1.0, 0.0, 0.0]\nmaterial = \"wall\"\n";
            let scene = load_scene_str(&trapped, std::path::Path::new("trapped.toml"))?;
            let (out, bad) = finite_render(gpu, &scene, &small(&scene, 48, 48, 1))?;
            let (o, m) = verdict(true, &bad, String::new());
            Ok((out.image.mean()[0], o, m))
        },
    ));
    let name = "grazing view along the floor (RING, camera at y = 0.001)";
    match embedded::load("ring") {
        Err(e) => cases.push(could_not_run(name, figure, &e.into())),
        Ok(ring) => cases.push(case(name, figure, || {
            let mut s = ring.clone();
            s.camera.position = Vec3::new(0.0, 0.001, 2.9);
            s.camera.look_at = Vec3::new(0.0, 0.001, 0.0);
            let (out, bad) = finite_render(gpu, &s, &small(&s, 64, 48, 1))?;
            let (o, m) = verdict(true, &bad, String::new());
            Ok((out.image.mean()[0], o, m))
        })),
    }
}

/// Renders `changed` and `original` at 64 x 48 and scores the first against
/// the second by relative MSE, with twice the original's seed-to-seed relative
/// MSE as the limit.
fn same_image(
    gpu: &Gpu,
    original: &Scene,
    changed: &Scene,
    detail: &str,
) -> Result<(f64, Outcome, String)> {
    let (w, h) = (64, 48);
    let base = render(gpu, original, &small(original, w, h, 1), &mut ())?;
    let other_seed = render(gpu, original, &small(original, w, h, 2), &mut ())?;
    let noise = compare(&other_seed.image, &base.image, None)?.rel_mse;
    let (out, bad) = finite_render(gpu, changed, &small(changed, w, h, 1))?;
    let e = compare(&out.image, &base.image, None)?.rel_mse;
    let (o, m) = verdict(
        e <= 2.0 * noise,
        &bad,
        format!("seed-to-seed {noise:.5}; {detail}"),
    );
    Ok((e, o, m))
}

/// Meshes: degenerate and duplicate triangles change nothing, and a mesh
/// file placed 1e6 from the origin renders as at the origin.
fn meshes(gpu: &Gpu, progress: &dyn Fn(&str), cases: &mut Vec<StressCase>) {
    use crate::scene::{Geometry, Shape};
    let figure = "relative MSE against the original (limit: 2 x seed-to-seed)";
    progress("degenerate and duplicate triangles");
    cases.push(case(
        "GLASS BALL plus degenerate triangles and its floor twice more as coincident triangles",
        figure,
        || {
            let original = embedded::load("glass_ball")?;
            let mut changed = original.clone();
            let floor = original.shapes[0];
            let Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            } = floor.geometry
            else {
                return Err(Error::InvalidOption(
                    "GLASS BALL's first shape is not its floor".into(),
                ));
            };
            let (a, b, c, d) = (
                corner,
                corner + edge1,
                corner + edge1 + edge2,
                corner + edge2,
            );
            let lifted = |p: Vec3| p + Vec3::new(0.0, 0.5, 0.0);
            let triangles = [
                (a, b, c),
                (a, c, d),
                (a, b, c),
                (a, c, d), // the floor, twice, coincident
                (
                    lifted(a),
                    lifted(c),
                    lifted(a) + 2.0 * (lifted(c) - lifted(a)),
                ), // collinear
                (lifted(b), lifted(b), lifted(b)), // a point
                (lifted(a), lifted(a), lifted(d)), // two equal vertices
            ];
            for (v0, v1, v2) in triangles {
                changed.shapes.push(Shape::new(
                    Geometry::Triangle { v0, v1, v2 },
                    floor.material,
                ));
            }
            same_image(gpu, &original, &changed, "7 triangles added")
        },
    ));
    progress("a mesh 1e6 from the origin");
    cases.push(case(
        "a 20,000-triangle OBJ mesh moved by 1e6 (MESH STAGE)",
        figure,
        || {
            let dir =
                tempfile::tempdir().map_err(|e| Error::io("create", std::env::temp_dir(), e))?;
            let obj = dir.path().join("ball.obj");
            let mesh = crate::scene::generate::uv_sphere(20_000, 0.0);
            std::fs::write(&obj, mesh.obj_text(None)).map_err(|e| Error::io("write", &obj, e))?;
            let stage = embedded::source("variants/mesh_stage").unwrap_or_default();
            let sphere = "type = \"sphere\"\ncenter = [0.0, 0.9, 0.0]\nradius = 0.9\n";
            if !stage.contains(sphere) {
                return Err(Error::InvalidOption(
                    "MESH STAGE has no ball to replace".into(),
                ));
            }
            let text = stage.replace(
                sphere,
                &format!(
                    "type = \"mesh\"\nfile = {:?}\nscale = 0.9\ntranslate = [0.0, 0.9, 0.0]\n",
                    obj.display().to_string()
                ),
            );
            let file = dir.path().join("stage.toml");
            let at_origin = load_scene_str(&text, &file)?;
            let moved = load_scene_str_translated(
                &text,
                &file,
                DVec3::new(1e6, -1e6, 1e6),
                Rebase::SceneCentre,
            )?;
            let o = moved.origin.to_array();
            same_image(gpu, &at_origin, &moved, &format!("local origin {o:?}"))
        },
    ));
}

/// SPPM run for thousands of iterations: no NaN or Inf anywhere in its state
/// and image, and every radius still positive (alpha 0.5 shrinks them fastest
/// of the usual choices).
fn progressive(gpu: &Gpu, progress: &dyn Fn(&str), cases: &mut Vec<StressCase>) {
    const ITERATIONS: u32 = 2000;
    progress("SPPM over 2000 iterations");
    cases.push(case(
        "SPPM over 2000 iterations (RING, 32 x 24, alpha 0.5, 1024 photons an iteration)",
        "smallest radius over the first (pixels that gathered photons)",
        || {
            let scene = embedded::load("ring")?;
            let options = small(&scene, 32, 24, 1);
            let sppm_options = crate::render::sppm::SppmOptions {
                iterations: ITERATIONS,
                alpha: 0.5,
                photons_per_iteration: 1024,
                ..Default::default()
            };
            let mut sppm = crate::render::sppm::Sppm::new(gpu, &scene, &options, &sppm_options)?;
            let mut timings = crate::timing::Timings::default();
            for _ in 0..ITERATIONS {
                sppm.iterate(&mut timings, &mut ())?;
            }
            let (flux, sums) = (sppm.state.flux.read_f32(), sppm.state.sums.read_f32());
            let image = sppm.image()?;
            let finite = |v: &[f32]| v.iter().all(|x| x.is_finite());
            let image_finite = image.pixels.iter().flatten().all(|x| x.is_finite());
            let mut bad = Vec::new();
            for (name, ok) in [
                ("state", finite(&flux) && finite(&sums)),
                ("image", image_finite),
            ] {
                if !ok {
                    bad.push(name);
                }
            }
            let smallest = flux
                .chunks(4)
                .zip(sums.chunks(4))
                .filter(|(_, s)| s[3] > 0.0)
                .map(|(f, _)| f[3].sqrt())
                .fold(f32::INFINITY, f32::min);
            let relative = f64::from(smallest / sppm.initial_radius);
            let (o, m) = verdict(
                smallest > 0.0 && smallest.is_finite(),
                &bad.join(", "),
                format!(
                    "first radius {}, smallest now {smallest:.3e}",
                    sppm.initial_radius
                ),
            );
            Ok((relative, o, m))
        },
    ));
}
