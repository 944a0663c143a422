//! Photon differentials and the footprint BVH (`--method differentials`):
//! the GPU's differentials equal their CPU twin on every record of a scene
//! with both kinds of light, a mirror and a glass sphere; through a plane
//! mirror and a ball lens they equal the analytic (paraxial) footprints; the
//! Morton order and the BVH's boxes equal a CPU build on the same footprints;
//! the walk finds exactly the footprints a brute-force check finds; the
//! estimate of a plane under a point light is its analytic irradiance, and
//! of a ball's with the curved footprint, which the paper's ellipsoid misses; and
//! the photons bounce as the option says, not as the scene file does.

use crate::common;

use glam::{Vec3, Vec4};
use photonmap::photon::differentials::{light_measures, FootprintShape};
use photonmap::render::{
    render, DifferentialsOptions, DifferentialsRun, Kernel, Method, RenderOptions, RenderOutput,
    WithPhotons,
};
use photonmap::scene::{Material, Scene};
use photonmap::twins::differentials::{self as twin, Footprint};
use photonmap::twins::photon::PhotonRecord;

fn run(scene: &Scene, w: u32, h: u32, o: DifferentialsOptions) -> RenderOutput {
    let mut options = RenderOptions::for_scene(scene);
    (options.width, options.height, options.seed) = (w, h, 5);
    options.method = Method::Differentials(WithPhotons {
        method: o,
        ..WithPhotons::default()
    });
    render(&common::gpu(), scene, &options, &mut ()).unwrap()
}

fn state(out: &RenderOutput) -> &DifferentialsRun {
    out.differentials_run().unwrap()
}

/// Every traced record, frames stacked.
fn records(run: &DifferentialsRun) -> Vec<PhotonRecord> {
    let f = &run.photons.frames;
    let v4 = |t: [f32; 4]| Vec4::from(t);
    let (p, q, i, o) = (
        common::texels(&f.position),
        common::texels(&f.power),
        common::texels(&f.incoming),
        common::texels(&f.outgoing),
    );
    let n = (f.width * f.frame_height * f.frames) as usize;
    (0..n)
        .map(|k| PhotonRecord {
            position: v4(p[k]),
            power: v4(q[k]),
            incoming: v4(i[k]),
            outgoing: v4(o[k]),
        })
        .collect()
}

/// The map's footprints read back, in Morton order.
fn footprints(run: &DifferentialsRun) -> Vec<Footprint> {
    let m = run.map.as_ref().unwrap();
    let [f0, f1, f2, f3] = m.footprints.each_ref().map(common::texels);
    (0..m.count as usize)
        .map(|i| Footprint {
            p: common::v3(f0[i]),
            area: f0[i][3],
            a: common::v3(f1[i]),
            diffuse: f1[i][3] != 0.0,
            b: common::v3(f2[i]),
            thickness: f2[i][3],
            power: common::v3(f3[i]),
            curved: m.options.shape.curved(),
        })
        .collect()
}

fn close(a: Vec3, b: Vec3, scale: f32) -> bool {
    (a - b).abs().max_element() <= 1e-3 * (b.abs().max_element() + scale)
}

/// Every record's differentials against the twin's on the same records, by
/// the interaction that follows the hit: none apart at a hit less grazing
/// than |d . n| = 0.05, where the transfer's division by the cosine
/// amplifies the shader's and the twin's different roundings.
fn twin_agreement(scene: &Scene, w: u32) -> [(usize, usize); 6] {
    let out = run(scene, w, w, DifferentialsOptions::default());
    let run = state(&out);
    let recs = records(run);
    let f = &run.photons.frames;
    let per_frame = (f.width * f.frame_height) as usize;
    let cpu = twin::record_differentials(scene, &recs, per_frame, &light_measures(scene, f));
    let d = &run.photons.differentials;
    let (a1, a2) = (common::texels(&d.axis1), common::texels(&d.axis2));
    let s = d.state.each_ref().map(common::texels);
    // (records, apart) by what follows the hit: absorbed, diffuse, mirror,
    // glass reflection, glass refraction; and grazing hits of any kind.
    let mut counts = [(0usize, 0usize); 6];
    for (i, (r, c)) in recs.iter().zip(&cpu).enumerate() {
        if i < per_frame || r.position.w < 0.0 {
            continue;
        }
        let next = r.outgoing.truncate();
        let d = r.incoming.truncate();
        let kind = if d.dot(c.normal).abs() < 0.05 {
            5
        } else if r.incoming.w == 0.0 {
            0
        } else {
            match scene.materials[r.position.w as usize] {
                Material::Diffuse { .. } => 1,
                Material::Mirror { .. } => 2,
                _ if next.dot(c.normal) > 0.0 => 3,
                _ => 4,
            }
        };
        let gpu_axis = [common::v3(a1[i]), common::v3(a2[i])];
        let dd1 = Vec3::new(s[0][i][3], s[1][i][3], s[2][i][3]);
        let gpu_out = [
            common::v3(s[0][i]),
            common::v3(s[1][i]),
            dd1,
            common::v3(s[2][i]),
        ];
        let cpu_out = [c.out.dp[0], c.out.dp[1], c.out.dd[0], c.out.dd[1]];
        let scale = c.axis[0].length().max(c.axis[1].length()) * 1e-2;
        let same = (0..2).all(|k| close(gpu_axis[k], c.axis[k], scale))
            && (0..4).all(|k| close(gpu_out[k], cpu_out[k], 1e-2 * cpu_out[k].length() + 1e-6))
            && (a1[i][3] != 0.0) == c.diffuse_at_hit;
        counts[kind].0 += 1;
        counts[kind].1 += usize::from(!same);
    }
    println!(
        "{}: (records, apart) absorbed {:?}, diffuse {:?}, mirror {:?}, glass reflection {:?}, glass refraction {:?}; grazing {:?}",
        scene.name, counts[0], counts[1], counts[2], counts[3], counts[4], counts[5]
    );
    for (kind, (n, apart)) in counts.iter().enumerate().take(5) {
        assert_eq!(
            *apart, 0,
            "kind {kind}: {apart} of {n} records apart from the twin"
        );
    }
    counts
}

/// Both kinds of light, a mirror sphere and a glass sphere, diffuse walls:
/// every interaction the differentials know, by enough records each.
#[test]
fn the_differentials_equal_their_cpu_twin_on_every_record() {
    let counts = twin_agreement(&common::fixture("mirror_box"), 24);
    for (kind, min) in [(1, 10_000), (2, 1_000), (3, 100), (4, 1_000)] {
        assert!(
            counts[kind].0 >= min,
            "kind {kind}: {} records",
            counts[kind].0
        );
    }
}

/// RING: a cylinder (the normal's differential has no part along its axis)
/// and projection maps (a kept fraction below 1 in the emission measure).
#[test]
fn the_differentials_equal_their_twin_on_ring_s_cylinder_and_projection_maps() {
    let ring = common::paper_scene("ring");
    let counts = twin_agreement(&ring, 8);
    assert!(counts[2].0 >= 1_000, "mirror hits: {}", counts[2].0);
}

/// A point light on the axis of a ball lens (or above a mirror), a diffuse
/// floor below: the footprint of the stored photon nearest the axis against
/// the paraxial one, |dp| = `expected` a unit emission angle.
fn axial_footprint(fixture: &str, bounces_before_floor: u32, expected: f32) {
    let scene = common::fixture(fixture);
    let out = run(&scene, 8, 8, DifferentialsOptions::default());
    let run = state(&out);
    let recs = records(run);
    let f = &run.photons.frames;
    let per_frame = (f.width * f.frame_height) as usize;
    let d = &run.photons.differentials;
    let (a1, a2) = (common::texels(&d.axis1), common::texels(&d.axis2));
    let frame = bounces_before_floor as usize + 1;
    let nearest = (frame * per_frame..(frame + 1) * per_frame)
        .filter(|&i| recs[i].position.w >= 0.0 && recs[i].power.w == 1.0)
        .filter(|&i| recs[i].position.y.abs() < 1e-4)
        .min_by(|&i, &j| {
            let rxz = |k: usize| Vec3::new(recs[k].position.x, 0.0, recs[k].position.z).length();
            rxz(i).total_cmp(&rxz(j))
        })
        .expect("a photon reaches the floor");
    let (u, v) = (common::v3(a1[nearest]), common::v3(a2[nearest]));
    let off_axis = Vec3::new(recs[nearest].position.x, 0.0, recs[nearest].position.z).length();
    println!(
        "nearest photon {off_axis:.4} off the axis: |dp| = {:.4}, {:.4} (paraxial {expected}); cos between them {:.2e}",
        u.length(),
        v.length(),
        u.normalize().dot(v.normalize())
    );
    for axis in [u, v] {
        assert!(
            ((axis.length() - expected) / expected).abs() < 0.01,
            "|dp| {} against {expected}",
            axis.length()
        );
    }
    assert!(
        u.normalize().dot(v.normalize()).abs() < 0.01,
        "the two semi-axes stay orthogonal"
    );
}

#[test]
fn through_a_ball_lens_the_footprint_is_the_paraxial_one() {
    // Light 1.5 above a ball of radius 0.5 (n = 1.5) whose bottom is 1 above
    // the floor. Ray-transfer matrices for a unit angle: after 1.5, height
    // 1.5; the first surface bends it to -1/3; after the 1.0 of glass, 7/6;
    // the second surface to -7/6 - 1/2 = -5/3; after 1.0 to the floor, -1/2.
    // Each refraction is the Fresnel branch of probability 1 - F, F =
    // ((n - 1) / (n + 1))^2 = 0.04 at normal incidence, which widens the
    // differentials by 1 / sqrt(1 - F) (section 4.2's rescaling): twice.
    let f = 0.04f32;
    axial_footprint("ball_lens", 2, 0.5 / (1.0 - f));
}

#[test]
fn off_a_plane_mirror_the_footprint_is_the_mirror_images() {
    // Light 2 above the floor, a mirror 1 above the light facing down: the
    // reflected photon comes from the light's image 4 above the floor.
    axial_footprint("plane_mirror", 1, 4.0);
}

#[test]
fn the_morton_order_and_the_bvh_equal_a_cpu_build_on_the_same_footprints() {
    let scene = common::fixture("mirror_box");
    // The paper's one map, whose every record has a footprint.
    let o = DifferentialsOptions {
        smoothing: Some(2.0),
        caustic_photons: Some(0),
        ..DifferentialsOptions::default()
    };
    let out = run(&scene, 8, 8, o.clone());
    let run = state(&out);
    let map = run.map.as_ref().unwrap();
    let recs = records(run);
    let f = &run.photons.frames;
    let per_frame = (f.width * f.frame_height) as usize;
    // The stored records of the photons in use, with their Morton codes.
    let mut keys: Vec<(i32, i32)> = recs
        .iter()
        .enumerate()
        .take(per_frame * f.frames as usize)
        .filter(|(i, r)| r.power.w != 0.0 && ((i % per_frame) as u32) < f.photons_used)
        .map(|(i, r)| {
            let code = twin::morton(r.position.truncate(), map.morton_lo, map.morton_scale);
            (code as i32, i as i32)
        })
        .collect();
    keys.sort();
    let sorted = map.sorted.read_i32();
    let gpu: Vec<(i32, i32)> = (0..map.count as usize)
        .map(|i| (sorted[2 * i], sorted[2 * i + 1]))
        .collect();
    assert_eq!(gpu.len(), keys.len(), "one footprint a stored record");
    let order_apart = gpu.iter().zip(&keys).filter(|(g, c)| g != c).count();
    // The footprints themselves, from the GPU's differentials.
    let d = &run.photons.differentials;
    let (a1, a2) = (common::texels(&d.axis1), common::texels(&d.axis2));
    let fps = footprints(run);
    let fo = o.footprint_options(&scene, 2.0);
    let mut footprint_apart = 0;
    for (fp, &(_, r)) in fps.iter().zip(&gpu) {
        let r = r as usize;
        let diff = twin::RecordDifferentials {
            axis: [common::v3(a1[r]), common::v3(a2[r])],
            diffuse_at_hit: a1[r][3] != 0.0,
            ..Default::default()
        };
        let mut c = twin::footprint(&recs[r], &diff, &fo, map.delta, f.power_scale);
        let material = recs[r].position.w as usize;
        c.area *= twin::coverage(&scene, &c, material, fo.coverage_samples, false);
        let same = close(fp.a, c.a, 1e-6)
            && close(fp.b, c.b, 1e-6)
            && (fp.area - c.area).abs() <= 1e-3 * c.area
            && fp.p == c.p
            && close(fp.power, c.power, 0.0);
        footprint_apart += usize::from(!same);
    }
    // The BVH over the GPU's footprints.
    let (leaves, boxes) = twin::node_boxes(&fps, map.leaf_size);
    assert_eq!(leaves, map.leaves);
    let (lo, hi) = (common::texels(&map.box_min), common::texels(&map.box_max));
    let size = scene.size();
    let mut box_apart = 0;
    for (i, (clo, chi)) in boxes.iter().enumerate().skip(1) {
        let tol = 1e-5 * size;
        let near = |g: Vec3, c: Vec3| (g - c).abs().max_element() <= tol || (g == c);
        if !(near(common::v3(lo[i]), *clo) && near(common::v3(hi[i]), *chi)) {
            box_apart += 1;
        }
    }
    println!(
        "{} footprints, leaf size {} (auto {}), {} leaves: {order_apart} apart in Morton order, {footprint_apart} footprints and {box_apart} of {} node boxes apart from the twin",
        map.count,
        map.leaf_size,
        map.auto_leaf_size,
        map.leaves,
        boxes.len() - 1
    );
    assert_eq!(order_apart, 0);
    assert_eq!(footprint_apart, 0);
    assert_eq!(box_apart, 0);
}

#[test]
fn the_walk_finds_exactly_the_footprints_brute_force_finds() {
    let scene = common::fixture("mirror_box");
    // A small leaf size makes a deep tree; Epanechnikov weights each find.
    let o = DifferentialsOptions {
        smoothing: Some(3.0),
        leaf_size: Some(3),
        kernel: Kernel::Epanechnikov,
        caustic_photons: Some(0),
        ..DifferentialsOptions::default()
    };
    let out = run(&scene, 32, 32, o);
    let walk = walk_against_brute_force(&out, true);
    println!(
        "{} pixels, {:.1} footprints each on average: {} apart from brute force, {} more on a footprint's boundary",
        walk.hits, walk.mean_found, walk.apart, walk.borderline
    );
    assert!(walk.mean_found > 5.0, "the walk has footprints to find");
    assert_eq!(walk.apart, 0);
}

/// The walk's sums at the first hits against the twin's brute force over
/// the same footprints.
struct WalkCheck {
    hits: usize,
    /// Hits whose count or sum is apart, off every footprint's boundary.
    apart: usize,
    /// Hits apart but within 1e-4 of some footprint's boundary, where f32
    /// may decide either way.
    borderline: usize,
    mean_found: f64,
}

fn walk_against_brute_force(out: &RenderOutput, epanechnikov: bool) -> WalkCheck {
    let run = state(out);
    let fps = footprints(run);
    let sum = common::texels(&run.estimate.sum);
    let x = common::texels(&out.state.direct.diffuse_position);
    let n = common::texels(&out.state.direct.diffuse_normal);
    let (mut hits, mut apart, mut borderline, mut found) = (0, 0, 0, 0u64);
    for i in 0..sum.len() {
        if x[i][3] <= 0.0 {
            continue;
        }
        hits += 1;
        let (p, nq) = (common::v3(x[i]), common::v3(n[i]));
        let (s, c) = twin::estimate(&fps, p, nq, epanechnikov);
        found += c as u64;
        let same =
            sum[i][3] as u32 == c && close(common::v3(sum[i]), s, 1e-3 * s.max_element() + 1e-9);
        if !same {
            let on_a_boundary = fps
                .iter()
                .any(|f| f.area > 0.0 && f.c().dot(nq) > 0.0 && f.on_boundary(p, nq, 1e-4));
            *(if on_a_boundary {
                &mut borderline
            } else {
                &mut apart
            }) += 1;
        }
    }
    WalkCheck {
        hits,
        apart,
        borderline,
        mean_found: found as f64 / hits.max(1) as f64,
    }
}

#[test]
fn a_plane_under_a_point_light_gets_its_analytic_irradiance() {
    // E(x) = I h / (h^2 + rho^2)^(3/2) on the floor, h = 1, I = 1; first hits
    // stored, each footprint 5 Delta dp (only-specular photons' factor).
    let scene = common::fixture("floor_under_point_light");
    let out = run(&scene, 48, 48, DifferentialsOptions::default());
    let run = state(&out);
    let sum = common::texels(&run.estimate.sum);
    let x = common::texels(&out.state.direct.diffuse_position);
    let (mut ratio, mut pixels) = (0.0f64, 0usize);
    for i in 0..sum.len() {
        let p = common::v3(x[i]);
        let rho = Vec3::new(p.x, 0.0, p.z).length();
        if x[i][3] <= 0.0 || rho > 0.5 {
            continue;
        }
        let analytic = 1.0 / (1.0 + rho * rho).powf(1.5);
        ratio += f64::from(sum[i][0] / analytic);
        pixels += 1;
    }
    let ratio = ratio / pixels as f64;
    // Noise: the photons whose footprints reach the disc; bias: the kernel's
    // second-order term, -0.75 (r / h)^2 of E at the axis for footprints of radius r.
    let fps = footprints(run);
    let near = fps
        .iter()
        .filter(|f| Vec3::new(f.p.x, 0.0, f.p.z).length() < 0.5 + f.a.length())
        .count();
    let r = fps.iter().map(|f| f.a.length()).sum::<f32>() / fps.len() as f32;
    let tolerance = 3.0 / (near as f64).sqrt() + 0.75 * f64::from(r * r);
    println!(
        "{pixels} pixels: mean estimate / analytic = {ratio:.4} (allowed 1 +- {tolerance:.4}: {near} photons reach the disc, footprint radius {r:.3})"
    );
    assert!((ratio - 1.0).abs() <= tolerance);
}

/// The ball under the point light rendered with `o`: the footprint
/// estimate over the first hits lit at cos >= 0.5 (the cap above y = 0.729)
/// over the analytic E(x) = I cos / d^2 (I = 1, light at (0, 3, 0), the
/// unit ball at the origin), the footprints' mean radius, how many of them
/// reach the cap, and the walk against brute force.
fn ball_estimate(o: DifferentialsOptions) -> (f64, f32, usize, WalkCheck) {
    let scene = common::fixture("ball_under_point_light");
    let out = run(&scene, 48, 48, o);
    let run = state(&out);
    let sum = common::texels(&run.estimate.sum);
    let x = common::texels(&out.state.direct.diffuse_position);
    let light = Vec3::new(0.0, 3.0, 0.0);
    let (mut ratio, mut pixels) = (0.0f64, 0usize);
    for i in 0..sum.len() {
        let p = common::v3(x[i]);
        let v = light - p;
        let cos = p.normalize().dot(v.normalize());
        if x[i][3] <= 0.0 || cos < 0.5 {
            continue;
        }
        ratio += f64::from(sum[i][0] / (cos / v.length_squared()));
        pixels += 1;
    }
    let fps = footprints(run);
    let radius = |f: &Footprint| f.a.length().max(f.b.length());
    let r = fps.iter().map(radius).sum::<f32>() / fps.len() as f32;
    let near = fps.iter().filter(|f| f.p.y > 0.729 - radius(f)).count();
    (
        ratio / pixels as f64,
        r,
        near,
        walk_against_brute_force(&out, false),
    )
}

/// On a ball, the paper's thin ellipsoid lets the surface's points near its
/// rim out (the ball falls away from the ellipse's plane by rho^2 / 2R) and
/// loses their share of the power; the curved footprint keeps them, so the
/// estimate meets the analytic irradiance within its noise and its kernel's
/// bias: the plane's, plus the ball's area under an ellipse of radius r
/// exceeding the ellipse's by (r / R)^2 / 4 at most. At these footprints
/// the ball falls away by less than their thickness, so a third run with
/// footprints five times as wide (the caustic factor 25), which the ball
/// leaves by several thicknesses, checks the walk and the boxes where the
/// depth allowance decides.
#[test]
fn on_a_ball_the_curved_footprint_keeps_the_light_the_ellipsoid_loses() {
    let with = |footprint_shape, caustic_smoothing| DifferentialsOptions {
        footprint_shape,
        caustic_smoothing,
        ..DifferentialsOptions::default()
    };
    let (curved, r, near, curved_walk) = ball_estimate(with(FootprintShape::Curved, 5.0));
    let (ellipsoid, _, _, ellipsoid_walk) = ball_estimate(with(FootprintShape::Ellipsoid, 5.0));
    let (_, wide_r, _, wide_walk) = ball_estimate(with(FootprintShape::Curved, 25.0));
    // Noise, the plane's kernel bias 0.75 (r / R)^2 with the ball's radius
    // for the height, and the ball's excess area (r / R)^2 / 4.
    let r = f64::from(r);
    let tolerance = 3.0 / (near as f64).sqrt() + r * r;
    println!(
        "estimate / analytic: curved {curved:.4}, ellipsoid {ellipsoid:.4} (allowed 1 +- {tolerance:.4}: {near} photons reach the cap, footprint radius {r:.3})"
    );
    for (name, w) in [
        ("curved".to_string(), &curved_walk),
        ("ellipsoid".to_string(), &ellipsoid_walk),
        (format!("curved, footprint radius {wide_r:.3}"), &wide_walk),
    ] {
        println!(
            "{name}: {} hits, {:.1} footprints each, {} apart from brute force, {} more on a footprint's boundary",
            w.hits, w.mean_found, w.apart, w.borderline
        );
        assert_eq!(w.apart, 0, "{name}");
        assert!(w.borderline * 100 <= w.hits, "{name}");
    }
    assert!(wide_r > 0.3, "{wide_r}");
    assert!((curved - 1.0).abs() <= tolerance);
    assert!(ellipsoid < 1.0 - tolerance);
}

/// The 1 x 1 floor square under the point light: most footprints (r_max 0.5)
/// overhang its edges.
fn square_under_point_light() -> Scene {
    let text = common::replace_once(
        &common::fixture_text("floor_under_point_light"),
        "corner = [-4.0, 0.0, -4.0]\nedge1 = [0.0, 0.0, 8.0]\nedge2 = [8.0, 0.0, 0.0]",
        "corner = [-0.5, 0.0, -0.5]\nedge1 = [0.0, 0.0, 1.0]\nedge2 = [1.0, 0.0, 0.0]",
    );
    let path = common::fixture_file("floor_under_point_light");
    photonmap::scene::load_scene_str(&text, &path).unwrap()
}

/// The share of a footprint's ellipse on the square |x|, |z| <= 0.5, by a
/// 64 x 64 polar grid uniform in area (independent of the probes' spiral).
fn share_on_square(f: &Footprint) -> f64 {
    let n = 64;
    let mut on = 0usize;
    for i in 0..n {
        for j in 0..n {
            let r = ((i as f32 + 0.5) / n as f32).sqrt();
            let phi = 2.0 * std::f32::consts::PI * (j as f32 + 0.5) / n as f32;
            let q = f.p + r * (phi.cos() * f.a + phi.sin() * f.b);
            on += usize::from(q.x.abs() <= 0.5 && q.z.abs() <= 0.5);
        }
    }
    on as f64 / (n * n) as f64
}

/// The estimate integrated over the surface keeps footprint i's power times
/// its true share on the surface over the share its area was divided by.
/// Without coverage probes the overhang is lost; with them each footprint's
/// area is its share of the ellipse (equal to the CPU twin's probes), so the
/// power kept is all of it, up to the probes' quadrature error.
#[test]
fn footprints_overhanging_an_edge_keep_their_power_with_coverage_probes() {
    let scene = square_under_point_light();
    let material = scene.shapes[0].material;
    let mut kept = Vec::new();
    for samples in [0, 16] {
        let o = DifferentialsOptions {
            coverage_samples: samples,
            ..DifferentialsOptions::default()
        };
        let out = run(&scene, 8, 8, o);
        let fps = footprints(state(&out));
        let (mut power, mut power_kept, mut overhanging, mut apart) = (0.0, 0.0, 0, 0);
        // The quadrature error of each share the probes found, against the grid's.
        let mut errors = Vec::new();
        for f in &fps {
            let ellipse = std::f32::consts::PI * f.a.cross(f.b).length();
            let share = f64::from(f.area / ellipse);
            let twin_share = twin::coverage(&scene, f, material, samples, false);
            apart += usize::from((f64::from(twin_share) - share).abs() > 1e-4);
            let truth = share_on_square(f);
            let p = f64::from(f.power.x);
            power += p;
            power_kept += p * truth / share;
            overhanging += usize::from(truth < 1.0);
            if samples > 0 && truth < 1.0 {
                errors.push(share - truth);
            }
        }
        let fraction = power_kept / power;
        let mean_error = errors.iter().sum::<f64>() / errors.len().max(1) as f64;
        println!(
            "{samples} probes: {} footprints, {overhanging} overhang; power kept {fraction:.4}; mean probe share - true share {mean_error:+.4}; {apart} apart from the twin",
            fps.len()
        );
        assert_eq!(apart, 0, "the probes' shares equal the twin's");
        kept.push((fraction, errors));
    }
    let (without, _) = &kept[0];
    let (with, errors) = &kept[1];
    // The spread of the probes' quadrature error over the footprints that
    // overhang bounds how far their mean, and so the power kept, may stray.
    let n = errors.len() as f64;
    let mean = errors.iter().sum::<f64>() / n;
    let sd = (errors.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let bound = 3.0 * sd / n.sqrt();
    println!("allowed: 1 +- {bound:.4} (quadrature error sd {sd:.4} over {n} footprints)");
    assert!(
        1.0 - without > bound,
        "without probes the overhang is lost: {without}"
    );
    assert!(
        (with - 1.0).abs() <= bound,
        "power kept with probes: {with}"
    );
}

/// The furnace (a closed diffuse sphere around a point light) at albedo 0.8,
/// whose photons its file lets bounce `bounces` times.
fn bright_furnace(bounces: u32) -> Scene {
    let text = common::replace_once(
        &common::replace_once(
            &common::fixture_text("furnace"),
            "albedo = [0.5, 0.5, 0.5]",
            "albedo = [0.8, 0.8, 0.8]",
        ),
        "max_bounces = 24",
        &format!("max_bounces = {bounces}"),
    );
    photonmap::scene::load_scene_str(&text, std::path::Path::new("furnace.toml")).unwrap()
}

fn mean_radiance(scene: &Scene, max_bounces: u32, seed: u32) -> (f64, Vec<[f32; 3]>) {
    let mut options = RenderOptions::for_scene(scene);
    (options.width, options.height, options.seed) = (32, 32, seed);
    options.method = Method::Differentials(WithPhotons {
        method: DifferentialsOptions {
            max_bounces,
            ..DifferentialsOptions::default()
        },
        ..WithPhotons::default()
    });
    let out = render(&common::gpu(), scene, &options, &mut ()).unwrap();
    let m = out.image.mean();
    ((m[0] + m[1] + m[2]) / 3.0, out.image.pixels.clone())
}

/// The photons bounce `max_bounces` times, not the file's max_bounces: in
/// the furnace at albedo 0.8 the light past the 8th bounce is rho^8 = 17% of
/// all. The file's count changes nothing, and 8 bounces lose light by far
/// more than the noise between seeds.
#[test]
fn differentials_photons_bounce_as_the_option_says_not_as_the_file_does() {
    let (short_file, long_file) = (bright_furnace(8), bright_furnace(32));
    let (a, image_a) = mean_radiance(&short_file, 32, 1);
    let (b, image_b) = mean_radiance(&long_file, 32, 1);
    assert!(image_a == image_b, "the file's max_bounces must not matter");
    let others: Vec<f64> = [2, 3]
        .iter()
        .map(|&s| mean_radiance(&long_file, 32, s).0)
        .collect();
    let (eight, _) = mean_radiance(&long_file, 8, 1);
    let all = [a, others[0], others[1]];
    let mean = all.iter().sum::<f64>() / 3.0;
    let sd = (all.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / 2.0).sqrt();
    println!("32 bounces: {all:.4?} (sd {sd:.4}); 8 bounces: {eight:.4}; {b:.4}");
    assert!(mean - eight > 6.0 * sd, "{mean} - {eight} against sd {sd}");
}
