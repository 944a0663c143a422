//! Instant global illumination: the VPL gather equals its CPU twin on the same
//! VPLs (exact and imperfect visibility), the discontinuity buffer and the
//! joint bilateral upsampling equal theirs on the gather's own output, in
//! the furnace, unbounded and with exact visibility, IGI converges to the
//! analytic answer as the VPL paths grow, and where no two diffuse surfaces
//! face each other it traces no VPLs, which would light nothing there.

use crate::common;

use glam::Vec3;
use photonmap::gpu::Texture;
use photonmap::render::{
    render, IgiOptions, Method, RenderOptions, RenderOutput, VplGather, Vpls, WithCausticMap,
};
use photonmap::scene::{Material, Scene};
use photonmap::twins::igi::{incident, Vpl};

fn options(scene: &Scene, w: u32, h: u32, seed: u32, igi: IgiOptions) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (w, h, seed);
    o.method = Method::Igi(WithCausticMap {
        method: igi,
        ..WithCausticMap::default()
    });
    o
}

fn mirror_box() -> Scene {
    common::fixture("mirror_box")
}

/// The VPLs and gather of an IGI render that traced them.
fn gather(out: &RenderOutput) -> &VplGather {
    out.igi_run().unwrap().gather.as_ref().unwrap()
}

fn vpls(out: &RenderOutput) -> Vec<Vpl> {
    twin_vpls(&gather(out).vpls)
}

/// The GPU's VPLs as the twin takes them.
fn twin_vpls(vpls: &Vpls) -> Vec<Vpl> {
    vpls.read()
        .into_iter()
        .map(|(p, n, i)| Vpl {
            position: Vec3::from(p),
            normal: Vec3::from(n),
            intensity: Vec3::from(i),
        })
        .collect()
}

/// A texture's texels as rgb.
fn rgb_texels(t: &Texture) -> Vec<Vec3> {
    common::texels(t).into_iter().map(common::v3).collect()
}

/// The CPU twin's light incident from `vpls`, bounded at `m`, at pixel `p`'s
/// first diffuse hit (`pos`, `nor`: the first-hit texels); zero without one.
fn twin_incident(
    scene: &Scene,
    vpls: &[Vpl],
    (pos, nor): (&[[f32; 4]], &[[f32; 4]]),
    p: usize,
    m: f32,
    imperfect: bool,
) -> Vec3 {
    if pos[p][3] <= 0.0 {
        return Vec3::ZERO;
    }
    incident(
        scene,
        vpls,
        common::v3(pos[p]),
        common::v3(nor[p]),
        m,
        imperfect,
    )
}

/// Pixels whose GPU and CPU values differ by more than float rounding allows.
fn apart(gpu: &[Vec3], cpu: &[Vec3]) -> (usize, f32) {
    let mut worst = 0f32;
    let n = gpu
        .iter()
        .zip(cpu)
        .filter(|(g, c)| {
            let d = (**g - **c).abs().max_element() / (c.max_element() + 1e-6);
            worst = worst.max(d);
            d > 1e-4
        })
        .count();
    (n, worst)
}

/// The gather at every pixel against the twin on the same VPLs and first hits.
#[test]
fn the_vpl_gather_equals_its_cpu_twin() {
    let gpu = common::gpu();
    let scene = mirror_box();
    for imperfect in [false, true] {
        let igi = IgiOptions {
            vpl_paths: 48,
            imperfect_visibility: imperfect,
            interleave: 1,
            ..IgiOptions::default()
        };
        let m = igi.min_distance_for(&scene);
        let out = render(&gpu, &scene, &options(&scene, 40, 36, 2, igi), &mut ()).unwrap();
        let v = vpls(&out);
        let pos = common::texels(&out.state.direct.diffuse_position);
        let nor = common::texels(&out.state.direct.diffuse_normal);
        let got = rgb_texels(&gather(&out).igi.incident);
        let twin: Vec<Vec3> = (0..pos.len())
            .map(|i| twin_incident(&scene, &v, (&pos, &nor), i, m, imperfect))
            .collect();
        let lit = twin.iter().filter(|c| c.max_element() > 0.0).count();
        let (n, worst) = apart(&got, &twin);
        eprintln!(
            "IGI gather ({} visibility): {} VPLs; {lit} of {} pixels lit; {n} apart beyond 1e-4 (largest relative difference {worst:.2e})",
            if imperfect { "imperfect" } else { "exact" },
            v.len(),
            got.len()
        );
        assert!(v.len() > 48, "every path leaves a VPL at its first hit");
        assert!(lit * 2 > got.len());
        // A shadow ray grazing an edge may decide differently in f32 on two
        // sides of the same rounding: a handful of VPLs, never a systematic gap.
        assert!(n * 100 <= got.len(), "{n} pixels apart");
    }
}

/// Interleaving: each pixel's gather sums only its subset, scaled by the
/// subsets (the twin on those VPLs), and the discontinuity buffer averages
/// the window's continuous neighbours (the twin on the GPU's gather).
/// Downsampling: the joint bilateral filter's twin on the GPU's low-resolution
/// light gives the GPU's full-resolution indirect light.
#[test]
fn interleaving_and_upsampling_equal_their_cpu_twins() {
    let gpu = common::gpu();
    let scene = mirror_box();
    let (w, h) = (40u32, 36u32);
    let igi = IgiOptions {
        vpl_paths: 48,
        interleave: 3,
        downsample: 2,
        ..IgiOptions::default()
    };
    let (n, f) = (igi.interleave as i32, igi.downsample as i32);
    let m = igi.min_distance_for(&scene);
    let out = render(&gpu, &scene, &options(&scene, w, h, 4, igi), &mut ()).unwrap();
    let v = vpls(&out);
    let state = &gather(&out).igi;
    let pos = common::texels(&out.state.direct.diffuse_position);
    let nor = common::texels(&out.state.direct.diffuse_normal);
    let thr = common::texels(&out.state.direct.diffuse_throughput);
    let (lw, lh) = (w.div_ceil(f as u32) as i32, h.div_ceil(f as u32) as i32);
    let shading = |qx: i32, qy: i32| -> usize {
        let (x, y) = (
            (qx * f + f / 2).min(w as i32 - 1),
            (qy * f + f / 2).min(h as i32 - 1),
        );
        (y * w as i32 + x) as usize
    };
    // The lattice points at offsets lo..lo + side (both axes, rows outer)
    // from `corner` that lie inside the lattice and have a first hit:
    // (offset, lattice point, pixel).
    let hit_neighbours = |corner: (i32, i32), lo: i32, side: i32| {
        let (pos, shading) = (&pos, &shading);
        (lo..lo + side)
            .flat_map(move |j| (lo..lo + side).map(move |i| (i, j)))
            .filter_map(move |(i, j)| {
                let (x, y) = (corner.0 + i, corner.1 + j);
                if x < 0 || y < 0 || x >= lw || y >= lh {
                    return None;
                }
                let p = shading(x, y);
                (pos[p][3] > 0.0).then_some(((i, j), (x, y), p))
            })
    };
    // The gather, subset by subset.
    let gathered = rgb_texels(&state.incident);
    let subsets = (n * n) as usize;
    let twin: Vec<Vec3> = (0..lw * lh)
        .map(|q| {
            let (qx, qy) = (q % lw, q / lw);
            let s = ((qx % n) + n * (qy % n)) as usize;
            let mine: Vec<Vpl> = v.iter().copied().skip(s).step_by(subsets).collect();
            let p = shading(qx, qy);
            twin_incident(&scene, &mine, (&pos, &nor), p, m, false) * subsets as f32
        })
        .collect();
    let (gather_apart, gather_worst) = apart(&gathered, &twin);
    // The discontinuity buffer on the GPU's gather.
    let eye = scene.camera.position;
    let filtered = rgb_texels(state.filtered_incident());
    let ncos = photonmap::layout::VPL_NORMAL_COS;
    let depth = photonmap::layout::VPL_DEPTH_TOLERANCE;
    let filter_twin: Vec<Vec3> = (0..lw * lh)
        .map(|q| {
            let (qx, qy) = (q % lw, q / lw);
            let p = shading(qx, qy);
            if pos[p][3] <= 0.0 {
                return gathered[q as usize];
            }
            let (x, nx) = (common::v3(pos[p]), common::v3(nor[p]));
            let tol = depth * eye.distance(x);
            let lo = -(n - 1) / 2;
            let (mut sum, mut count) = (Vec3::ZERO, 0.0);
            for ((i, j), (ox, oy), op) in hit_neighbours((qx, qy), lo, n) {
                if (i, j) != (0, 0)
                    && (common::v3(nor[op]).dot(nx) < ncos
                        || (common::v3(pos[op]) - x).dot(nx).abs() > tol)
                {
                    continue;
                }
                sum += gathered[(oy * lw + ox) as usize];
                count += 1.0;
            }
            sum / count
        })
        .collect();
    let (filter_apart, filter_worst) = apart(&filtered, &filter_twin);
    // The gather's occlusion query counts the shading points with a hit.
    let points = (0..lw * lh)
        .filter(|&q| pos[shading(q % lw, q / lw)][3] > 0.0)
        .count() as u64;
    assert_eq!(out.igi()[0].shading_points, points);
    // The joint bilateral upsampling on the GPU's filtered light.
    let albedo = |mat: f32| -> Vec3 {
        match scene.materials[mat as usize - 1] {
            Material::Diffuse { albedo } => albedo,
            _ => Vec3::ZERO,
        }
    };
    let indirect = rgb_texels(&state.indirect);
    let up_twin: Vec<Vec3> = (0..(w * h) as i32)
        .map(|p| {
            let (px, py) = (p % w as i32, p / w as i32);
            let pi = p as usize;
            if pos[pi][3] <= 0.0 || nor[pi][3] < 1.0 {
                return Vec3::ZERO;
            }
            let np = common::v3(nor[pi]);
            let (ux, uy) = (
                (px as f32 - (f / 2) as f32) / f as f32,
                (py as f32 - (f / 2) as f32) / f as f32,
            );
            let (bx, by) = (ux.floor() as i32 - 1, uy.floor() as i32 - 1);
            let (mut sum, mut k) = (Vec3::ZERO, 0.0f32);
            for (_, (qx, qy), qp) in hit_neighbours((bx, by), 0, 4) {
                let x = common::v3(pos[pi]);
                if (common::v3(pos[qp]) - x).dot(np).abs() > depth * eye.distance(x) {
                    continue;
                }
                let range = np.dot(common::v3(nor[qp]));
                if range <= 0.0 {
                    continue;
                }
                let (dx, dy) = (ux - qx as f32, uy - qy as f32);
                let wgt = (-0.5 * (dx * dx + dy * dy)).exp() * range;
                sum += wgt * filtered[(qy * lw + qx) as usize];
                k += wgt;
            }
            let e = if k > 0.0 {
                sum / k
            } else {
                let qx = ((ux + 0.5).floor() as i32).clamp(0, lw - 1);
                let qy = ((uy + 0.5).floor() as i32).clamp(0, lh - 1);
                filtered[(qy * lw + qx) as usize]
            };
            common::v3(thr[pi]) * albedo(nor[pi][3]) / std::f32::consts::PI * e
        })
        .collect();
    let (up_apart, up_worst) = apart(&indirect, &up_twin);
    eprintln!(
        "IGI interleave 3, downsample 2: gather apart at {gather_apart} of {} ({gather_worst:.1e}); discontinuity buffer apart at {filter_apart} ({filter_worst:.1e}); upsampling apart at {up_apart} of {} ({up_worst:.1e})",
        gathered.len(),
        indirect.len()
    );
    assert!(gather_apart * 100 <= gathered.len(), "{gather_apart}");
    assert_eq!(filter_apart, 0);
    assert_eq!(up_apart, 0);
}

/// The furnace (a closed diffuse sphere of albedo 1/2 and radius 1, a point
/// light of intensity 1 at its centre) has L = 1 / pi everywhere. Inside a
/// sphere cos(theta_x) cos(theta_y) / d^2 = 1 / (4 R^2) for any two points,
/// so IGI unbounded with exact visibility is exact but for the VPLs' own
/// sampling: each path leaves a geometric number of VPLs (Russian roulette
/// at 1/2), so the total's relative error is at most 1 / sqrt(2 N) for N
/// independent paths (Halton paths do better). It must shrink as N grows,
/// and stay within 3 of those standard deviations.
#[test]
fn igi_in_the_furnace_converges_to_the_analytic_answer() {
    let gpu = common::gpu();
    let scene = common::fixture("furnace");
    let expected = 1.0 / std::f64::consts::PI;
    let mut errors = Vec::new();
    for paths in [16u32, 256, 4096] {
        let igi = IgiOptions {
            vpl_paths: paths,
            min_distance: Some(0.0),
            interleave: 1,
            ..IgiOptions::default()
        };
        let out = render(&gpu, &scene, &options(&scene, 16, 16, 1, igi), &mut ()).unwrap();
        let mean = out.image.mean()[0];
        let err = (mean / expected - 1.0).abs();
        let bound = 3.0 / (2.0 * paths as f64).sqrt();
        eprintln!(
            "furnace, IGI {paths} paths ({} VPLs): mean {mean:.5} against {expected:.5} ({:+.3}%, 3 sigma of independent paths {:.2}%)",
            out.vpls().unwrap().vpls,
            100.0 * (mean / expected - 1.0),
            100.0 * bound
        );
        assert!(err < bound, "{paths} paths: {err}");
        errors.push(err);
    }
    assert!(errors[2] < errors[0], "{errors:?}");
}

/// IGI unbounded with exact visibility against the independent CPU path
/// tracer (next-event estimation) on a closed diffuse box lit by a point and
/// an area light, the scene SPPM is checked on: block means over the
/// interior 6 x 6 blocks of 4 x 4 pixels, with the variance of two IGI runs
/// on independent VPL sets (their mean's, (a - b)^2 / 4) and the path
/// tracer's own. chi^2/n must fall as the VPL paths grow and end within the
/// bound the SPPM test uses (3).
#[test]
fn igi_converges_to_the_path_tracer_as_vpls_grow() {
    let gpu = common::gpu();
    let scene = common::fixture("two_light_box");
    let pt = photonmap::twins::path_trace::path_trace(&scene, 32, 32, 1024, 11);
    let mut chi = Vec::new();
    for paths in [64u32, 4096] {
        let runs: Vec<photonmap::render::Image> = [1u32, 2]
            .iter()
            .map(|&seed| {
                let igi = IgiOptions {
                    vpl_paths: paths,
                    min_distance: Some(0.0),
                    interleave: 1,
                    ..IgiOptions::default()
                };
                let mut o = options(&scene, 32, 32, seed, igi);
                o.spp = 4;
                render(&gpu, &scene, &o, &mut ()).unwrap().image
            })
            .collect();
        let (_, chi2_n, worst) = common::blocks_against_path_tracer(&pt, [&runs[0], &runs[1]]);
        eprintln!(
            "two-light box, IGI {paths} paths x 2 seeds, 4 spp: chi^2/n = {chi2_n:.2}, largest relative difference {:.2}%",
            100.0 * worst
        );
        chi.push((chi2_n, worst));
    }
    assert!(chi[1].1 < chi[0].1, "{chi:?}");
    assert!(chi[1].0 < 3.0, "{chi:?}");
}

/// CORNELL BOX with its balls black and diffuse, so that the CPU path tracer
/// (independent of IGI) can render it: the ceiling is lit only indirectly,
/// mostly by the floor, whose plane faces it. IGI unbounded on many VPLs
/// matches the path tracer there, within three standard deviations of the
/// two (IGI's from two seeds' spread, the path tracer's own) and 2% for the
/// VPLs' sampling. A VPL shadow ray that starts lifted off x but runs
/// parallel to x -> y meets the floor's plane before the VPL and is blocked
/// by it; that lost a quarter of the ceiling's light.
#[test]
fn igi_lights_a_ceiling_from_the_floor_it_faces_as_the_path_tracer_does() {
    let gpu = common::gpu();
    let mut scene = common::paper_scene("cornell_box");
    for m in scene.materials.iter_mut() {
        if m.is_specular() {
            *m = Material::Diffuse { albedo: Vec3::ZERO };
        }
    }
    let (w, h) = (32u32, 32u32);
    let pt = photonmap::twins::path_trace::path_trace(&scene, w, h, 512, 3);
    // The ceiling's band: rows 1..4, columns 6..26, all ceiling at this size
    // (row 0 looks out past its front edge, row 4 reaches the light).
    let band: Vec<usize> = (1..4)
        .flat_map(|y| (6..26).map(move |x| y * w as usize + x))
        .collect();
    let lum = |p: [f64; 3]| (p[0] + p[1] + p[2]) / 3.0;
    let pt_mean = band.iter().map(|&i| lum(pt.mean[i])).sum::<f64>() / band.len() as f64;
    let pt_var = band
        .iter()
        .map(|&i| lum(pt.variance_of_mean[i]))
        .sum::<f64>()
        / (band.len() * band.len()) as f64;
    let means: Vec<f64> = [1u32, 2]
        .iter()
        .map(|&seed| {
            let igi = IgiOptions {
                vpl_paths: 2048,
                min_distance: Some(0.0),
                interleave: 1,
                ..IgiOptions::default()
            };
            let mut o = options(&scene, w, h, seed, igi);
            o.spp = 4;
            let img = render(&gpu, &scene, &o, &mut ()).unwrap().image;
            let pix = |i: usize| img.pixels[i].iter().map(|&v| v as f64).sum::<f64>() / 3.0;
            band.iter().map(|&i| pix(i)).sum::<f64>() / band.len() as f64
        })
        .collect();
    let igi = 0.5 * (means[0] + means[1]);
    let sigma = ((means[0] - means[1]).powi(2) / 4.0 + pt_var).sqrt();
    eprintln!(
        "ceiling band: IGI {igi:.5} (seeds {:.5}, {:.5}) against the path tracer's {pt_mean:.5}: ratio {:.4}, sigma {:.5}",
        means[0],
        means[1],
        igi / pt_mean,
        sigma
    );
    assert!(
        (igi - pt_mean).abs() < 3.0 * sigma + 0.02 * pt_mean,
        "IGI {igi} against {pt_mean}"
    );
}

/// Where every diffuse surface lies in one plane (GLASS BALL's floor under
/// the glass ball), VPLs light nothing: traced there anyway, the CPU twin's
/// gather of them is zero at every first hit of the render. So IGI traces
/// none and compensates nothing there, and its image is the caustic map's
/// (with the direct light) alone.
#[test]
fn igi_skips_vpls_where_no_two_diffuse_surfaces_face() {
    use photonmap::render::Timings;
    use photonmap::scene::pack::SceneTextures;
    let gpu = common::gpu();
    let scene = common::paper_scene("glass_ball");
    assert!(!scene.has_diffuse_interreflection());
    let igi = IgiOptions::default();
    let m = igi.min_distance_for(&scene);
    let out = render(&gpu, &scene, &options(&scene, 32, 24, 3, igi), &mut ()).unwrap();
    let run = out.igi_run().unwrap();
    assert!(run.report.skipped && run.gather.is_none() && run.stats.is_empty());
    assert!(run.compensation.is_none());
    assert!(
        out.image.mean()[0] > 0.0,
        "direct light and caustics remain"
    );

    let textures = SceneTextures::new(&gpu, &scene).unwrap();
    let traced = Vpls::trace(
        &gpu,
        &scene,
        &textures,
        (256, 32),
        7,
        &mut Timings::default(),
    )
    .unwrap();
    let v = twin_vpls(&traced);
    assert!(
        v.len() >= 64,
        "a quarter of the paths reach the floor: {}",
        v.len()
    );
    let pos = common::texels(&out.state.direct.diffuse_position);
    let nor = common::texels(&out.state.direct.diffuse_normal);
    let hits = pos.iter().filter(|p| p[3] > 0.0).count();
    assert!(hits * 2 > pos.len(), "most pixels see the floor: {hits}");
    let lit = (0..pos.len())
        .filter(|&i| twin_incident(&scene, &v, (&pos, &nor), i, m, false).max_element() > 0.0)
        .count();
    eprintln!(
        "GLASS BALL: {} VPLs traced anyway light {lit} of {hits} first hits",
        v.len()
    );
    assert_eq!(lit, 0);
}
