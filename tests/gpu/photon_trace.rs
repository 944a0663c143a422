//! Breadth-first photon tracing on the GPU against the CPU twin fed the same
//! random numbers, photon by photon, and stored flux against a closed form.

use crate::common;

use glam::{Vec3, Vec4};
use photonmap::photon::{PhotonTracer, RandomSource, TraceConfig};
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::{load_scene_str, Scene};
use photonmap::twins::photon::{trace_photons, PhotonRecord};

fn records(frames: &photonmap::photon::PhotonFrames) -> Vec<PhotonRecord> {
    let (p, w, i, o) = (
        frames.position.read_f32(),
        frames.power.read_f32(),
        frames.incoming.read_f32(),
        frames.outgoing.read_f32(),
    );
    (0..p.len() / 4)
        .map(|k| PhotonRecord {
            position: Vec4::from_slice(&p[4 * k..]),
            power: Vec4::from_slice(&w[4 * k..]),
            incoming: Vec4::from_slice(&i[4 * k..]),
            outgoing: Vec4::from_slice(&o[4 * k..]),
        })
        .collect()
}

fn close(a: Vec4, b: Vec4, scale: f32) -> bool {
    (a.truncate() - b.truncate()).abs().max_element() <= 1e-4 * scale
}

/// Compares GPU and CPU records photon by photon. A photon's path may leave
/// its twin's only where f32 rounding flips a decision (a Fresnel or roulette
/// draw at its threshold, a silhouette, a near-tie between surfaces); from then
/// on that photon is not compared. Returns (photons compared, photons diverged,
/// records matched).
fn compare(scene: &Scene, seed: u32, emitted: u32) -> (usize, usize, usize) {
    let gpu = common::gpu();
    let textures = SceneTextures::new(&gpu, scene).unwrap();
    let tracer = PhotonTracer::new(&gpu).unwrap();
    let frames = tracer.trace(scene, &textures, seed, emitted).unwrap();
    let gpu_records = records(&frames);
    let cpu_records = trace_photons(
        scene,
        frames.projection.as_ref(),
        seed,
        emitted,
        frames.width,
        frames.frame_height,
    );
    assert_eq!(gpu_records.len(), cpu_records.len());
    let per_frame = (frames.width * frames.frame_height) as usize;
    let size = scene.size();
    let (mut diverged, mut matched) = (0, 0);
    for photon in 0..emitted as usize {
        for f in 0..frames.frames as usize {
            let (g, c) = (
                gpu_records[f * per_frame + photon],
                cpu_records[f * per_frame + photon],
            );
            let flags_equal = g.position.w == c.position.w
                && g.power.w == c.power.w
                && g.incoming.w == c.incoming.w
                && g.outgoing.w == c.outgoing.w;
            let power_scale = c.power.truncate().max_element().max(1e-30);
            let values_close = close(g.position, c.position, size)
                && (g.power.truncate() - c.power.truncate())
                    .abs()
                    .max_element()
                    <= 1e-4 * power_scale
                && close(g.incoming, c.incoming, 1.0)
                && close(g.outgoing, c.outgoing, 1.0);
            if flags_equal && values_close {
                matched += 1;
            } else {
                diverged += 1;
                break;
            }
        }
    }
    (emitted as usize, diverged, matched)
}

#[test]
fn gpu_photons_equal_the_cpu_tracer_photon_by_photon() {
    // Caustics only: emission through projection maps, photons ending at
    // diffuse hits. Specular-last only: every path, stored after mirrors and
    // glass alone.
    for (name, emitted, caustics_only, specular_last_only) in [
        ("cornell_box", 20_000, false, false),
        ("glass_ball", 20_000, false, false),
        ("ring", 20_000, false, false),
        ("cornell_box", 10_000, true, false),
        ("ring", 10_000, true, false),
        ("cornell_box", 10_000, false, true),
    ] {
        let mut scene = common::paper_scene(name);
        scene.photon_map.caustics_only = caustics_only;
        scene.photon_map.specular_last_only = specular_last_only;
        let (photons, diverged, matched) = compare(&scene, 11, emitted);
        eprintln!("{name} (caustics only: {caustics_only}, specular-last only: {specular_last_only}): {photons} photons, {matched} records equal within 1e-4, {diverged} photons diverged");
        // Rounding flips a decision for a handful of photons in tens of thousands:
        // more than 0.5% would mean a real difference between the twins.
        assert!(
            diverged * 200 <= photons,
            "{name}: {diverged} of {photons} photons diverged"
        );
        assert!(
            matched > photons * 2,
            "{name}: too few records ({matched}) to have tested bounces"
        );
    }
}

/// The specular-last map traces the same paths as the all-paths one (same
/// seed, same numbers) and stores exactly those of its records whose photon
/// arrived from a mirror or glass: in CORNELL BOX, light through the balls
/// after the walls (L D+ S+ D) as well as the caustics straight from the light.
#[test]
fn specular_last_photons_are_the_records_that_arrived_from_a_mirror_or_glass() {
    let gpu = common::gpu();
    let mut scene = common::paper_scene("cornell_box");
    let textures = SceneTextures::new(&gpu, &scene).unwrap();
    let tracer = PhotonTracer::new(&gpu).unwrap();
    let all = records(&tracer.trace(&scene, &textures, 5, 8192).unwrap());
    scene.photon_map.specular_last_only = true;
    let frames = tracer.trace(&scene, &textures, 5, 8192).unwrap();
    let last = records(&frames);
    assert_eq!(all.len(), last.len());
    let per_frame = (frames.width * frames.frame_height) as usize;
    let specular = |mat: f32| mat >= 0.0 && scene.materials[mat as usize].is_specular();
    let (mut stored, mut after_diffuse) = (0, 0);
    for (i, (a, b)) in all.iter().zip(&last).enumerate() {
        assert_eq!(
            (a.position, a.outgoing),
            (b.position, b.outgoing),
            "record {i}"
        );
        let arrived_from_specular = i >= per_frame && specular(all[i - per_frame].position.w);
        let expected = a.power.w == 1.0 && arrived_from_specular;
        assert_eq!(b.power.w == 1.0, expected, "record {i}");
        if expected {
            stored += 1;
            // The photon met a diffuse surface before the mirror or glass.
            let earlier = (1..i / per_frame).any(|f| {
                let m = all[i - f * per_frame].position.w;
                m >= 0.0 && !specular(m)
            });
            after_diffuse += earlier as usize;
        }
    }
    eprintln!(
        "specular-last photons: {stored} stored, {after_diffuse} of them after a diffuse hit"
    );
    assert!(
        stored > 100 && after_diffuse * 4 > stored,
        "{stored}, {after_diffuse}"
    );
}

/// A scene of OBJ meshes: emissive triangles of unequal areas in two groups
/// (two `Triangles` lights), and UV spheres with vertex normals of glass,
/// mirror and diffuse material, on a diffuse floor.
fn obj_scene() -> Scene {
    let dir = common::TempDir::new("photon_twin_obj");
    common::write_sphere_obj(&dir.join("sphere.obj"), 400, true);
    std::fs::write(
        dir.join("lamps.mtl"),
        "newmtl warm\nKe 8 6 4\nnewmtl cold\nKe 2 3 5\n",
    )
    .unwrap();
    // Group `a`: a quad and a small triangle; group `b`: one tilted
    // triangle. All face down.
    std::fs::write(
        dir.join("lamps.obj"),
        "mtllib lamps.mtl\no a\nusemtl warm\n\
         v -1 3 -1\nv 0 3 -1\nv 0 3 0\nv -1 3 0\nv 0.2 3 0.2\nv 0.5 3 0.2\nv 0.2 3 0.4\n\
         f 1 2 3 4\nf 5 6 7\n\
         o b\nusemtl cold\nv 1 2.5 1\nv 2 2.8 1\nv 1 2.6 2\nf 8 9 10\n",
    )
    .unwrap();
    let mut text = r#"
[camera]
position = [0.0, 2.0, 6.0]
look_at = [0.0, 0.5, 0.0]
vfov = 40.0
width = 8
height = 8
[photon_map]
max_bounces = 6
[materials]
floor = { type = "diffuse", albedo = [0.7, 0.6, 0.5] }
glass = { type = "glass", ior = 1.5 }
mirror = { type = "mirror", reflectance = [0.9, 0.8, 0.7] }
clay = { type = "diffuse", albedo = [0.6, 0.6, 0.3] }
[[shape]]
type = "parallelogram"
corner = [-3.0, 0.0, -3.0]
edge1 = [0.0, 0.0, 6.0]
edge2 = [6.0, 0.0, 0.0]
material = "floor"
"#
    .to_string();
    for (scale, translate, material) in [
        (0.6, [-0.8, 0.6, 0.0], "glass"),
        (0.4, [0.8, 0.4, 0.5], "mirror"),
        (0.5, [0.3, 0.5, -1.2], "clay"),
    ] {
        text += &format!(
            "[[shape]]\ntype = \"mesh\"\nfile = \"sphere.obj\"\nscale = {scale}\ntranslate = {translate:?}\nmaterial = \"{material}\"\n"
        );
    }
    text += "[[shape]]\ntype = \"mesh\"\nfile = \"lamps.obj\"\n";
    load_scene_str(&text, &dir.join("obj_twin.toml")).unwrap()
}

#[test]
fn gpu_photons_from_emissive_triangles_and_off_shaded_meshes_equal_the_cpu_tracer() {
    let mut scene = obj_scene();
    assert_eq!(scene.lights.len(), 2);
    for caustics_only in [false, true] {
        scene.photon_map.caustics_only = caustics_only;
        let (photons, diverged, matched) = compare(&scene, 13, 20_000);
        eprintln!("OBJ scene (caustics only: {caustics_only}): {photons} photons, {matched} records equal within 1e-4, {diverged} photons diverged");
        assert!(
            diverged * 200 <= photons,
            "{diverged} of {photons} photons diverged"
        );
        assert!(matched > photons * 2, "too few records ({matched})");
    }
}

#[test]
fn stored_flux_on_a_plane_matches_the_solid_angle() {
    let gpu = common::gpu();
    // The fixture's floor half side, light height and intensity.
    let (half, height, intensity) = (2.0f32, 1.0f32, 3.0f32);
    let scene = common::fixture("plane_under_point_light");
    let textures = SceneTextures::new(&gpu, &scene).unwrap();
    let tracer = PhotonTracer::new(&gpu).unwrap();
    // Solid angle of a 2a x 2a square at distance h, seen from above its centre.
    let a2 = (half * half) as f64;
    let omega = 4.0 * (a2 / (a2 + (height * height) as f64)).asin();
    let expected = intensity as f64 * omega;
    let total_power = 4.0 * std::f64::consts::PI * intensity as f64;
    let p = omega / (4.0 * std::f64::consts::PI);

    for emitted in [10_000u32, 100_000] {
        let frames = tracer.trace(&scene, &textures, 5, emitted).unwrap();
        let flux: f64 = records(&frames)
            .iter()
            .filter(|r| r.power.w == 1.0)
            .map(|r| r.power.x as f64)
            .sum();
        let sigma = total_power / emitted as f64 * (emitted as f64 * p * (1.0 - p)).sqrt();
        eprintln!("{emitted} photons: flux {flux:.5}, analytic {expected:.5}, sigma {sigma:.5}");
        assert!(
            (flux - expected).abs() < 4.0 * sigma,
            "flux {flux} vs {expected} (sigma {sigma})"
        );
    }

    // Hitting the stored count: the map holds the target (or the last photon's
    // few extra records), and the scaled flux is still right.
    let (frames, report) = tracer.trace_to_stored(&scene, &textures, 9).unwrap();
    assert!(
        report.stored >= 20_000 && report.stored <= 20_000 + scene.photon_map.max_bounces,
        "{report:?}"
    );
    assert_eq!(frames.stored(), report.stored);
    // The GPU count pass equals the read-back count, photon by photon.
    assert_eq!(
        tracer.stored_per_photon(&frames).unwrap(),
        frames.stored_per_photon()
    );
    let per_frame = (frames.width * frames.frame_height) as usize;
    let flux: f64 = records(&frames)
        .iter()
        .enumerate()
        .filter(|(k, r)| r.power.w == 1.0 && (k % per_frame) < frames.photons_used as usize)
        .map(|(_, r)| r.power.x as f64 * frames.power_scale as f64)
        .sum();
    let used = frames.photons_used as f64;
    let sigma = total_power / used * (used * p * (1.0 - p)).sqrt();
    assert!(
        (flux - expected).abs() < 4.0 * sigma,
        "flux {flux} vs {expected} after choosing the emitted count ({report:?})"
    );
    let _ = Vec3::ZERO;
}

#[test]
fn the_random_texture_traces_the_same_photons_as_the_hash() {
    let gpu = common::gpu();
    let scene = common::paper_scene("cornell_box");
    let textures = SceneTextures::new(&gpu, &scene).unwrap();
    let with = |random| {
        PhotonTracer::with_config(
            &gpu,
            TraceConfig {
                random,
                ..TraceConfig::default()
            },
        )
        .unwrap()
    };
    let (hash, texture) = (with(RandomSource::Hash), with(RandomSource::Texture));
    let a = records(&hash.trace(&scene, &textures, 3, 5000).unwrap());
    let b = records(&texture.trace(&scene, &textures, 3, 5000).unwrap());
    assert_eq!(
        a, b,
        "--faithful's random texture must reproduce the hash's photons"
    );
    let c = records(&texture.trace(&scene, &textures, 4, 5000).unwrap());
    assert_ne!(a, c, "another seed, other photons");
}

#[test]
fn bounces_stop_when_no_photon_is_left_and_the_image_does_not_change() {
    use photonmap::render::{render, RenderOptions};
    let gpu = common::gpu();
    let text = include_str!("../../scenes/tests/furnace.toml")
        .replace("max_bounces = 24", "max_bounces = 64");
    let scene = load_scene_str(&text, std::path::Path::new("furnace64.toml")).unwrap();
    let options = |all: bool| {
        let mut o = RenderOptions::for_scene(&scene);
        (o.width, o.height) = (32, 32);
        if let Some(gi) = o.photon_map_mut() {
            gi.photons.all_bounces = all;
        }
        o
    };
    let run = |all: bool| render(&gpu, &scene, &options(all), &mut ()).unwrap();
    let (stopped, full) = (run(false), run(true));
    assert_eq!(
        stopped.image, full.image,
        "stopping early must not change the image"
    );
    let frames = |r: &photonmap::render::RenderOutput| {
        r.explain(&scene, &options(false))
            .iter()
            .find(|l| l.stage == "trace photons")
            .unwrap()
            .passes
    };
    assert_eq!(frames(&full), 65);
    assert!(frames(&stopped) < 40, "{} frames traced", frames(&stopped));
}

/// Projection maps are conservative: every direction from every point of a
/// light that meets a mirror or glass shape lies in a kept cell. Checked by
/// brute force over random light points and directions, with the emission's
/// own mapping, against the exact intersection of each specular shape.
#[test]
fn projection_maps_keep_every_direction_that_reaches_a_specular_shape() {
    use photonmap::photon::projection::emission_direction;
    use photonmap::photon::ProjectionMaps;
    use photonmap::scene::Light;
    use photonmap::twins::intersect::intersect_geometry;
    use photonmap::twins::light::area_light_point;
    use photonmap::twins::random::{rng_init, rng_next};
    for name in ["glass_ball", "ring", "cornell_box"] {
        let mut scene = common::paper_scene(name);
        scene.photon_map.caustics_only = true;
        let maps = ProjectionMaps::for_scene(&scene);
        let specular: Vec<_> = scene
            .shapes
            .iter()
            .filter(|s| scene.materials[s.material].is_specular())
            .collect();
        let (mut hits, samples) = (0u32, 400_000u32);
        for (light, map) in scene.lights.iter().zip(&maps.maps) {
            let mut rng = rng_init(7, [0, 0], 0);
            for _ in 0..samples {
                let (a, b) = (rng_next(&mut rng), rng_next(&mut rng));
                let (u, v) = (rng_next(&mut rng), rng_next(&mut rng));
                let origin = match *light {
                    Light::Point { position, .. } => position,
                    Light::Area { .. } => area_light_point(light, a, b),
                    Light::Triangles { .. } => unreachable!("the paper scenes have none"),
                };
                let d = emission_direction(light, u, v);
                if specular
                    .iter()
                    .any(|s| intersect_geometry(&s.geometry, origin, d).is_some())
                {
                    hits += 1;
                    assert!(
                        map.keeps(u, v),
                        "{name}: direction {d} from {origin} reaches a specular shape but its cell {} is not kept",
                        map.cell_of(u, v)
                    );
                }
            }
        }
        let reaching = hits as f64 / samples as f64;
        let kept = maps.kept_power_fraction(&scene);
        eprintln!(
            "{name}: {:.2}% of sampled directions reach a specular shape; {:.2}% of the power kept",
            100.0 * reaching,
            100.0 * kept
        );
        assert!(
            hits > 1000,
            "{name}: too few directions reach a specular shape ({hits}) to test the map"
        );
        assert!(kept < 1.0, "{name}: every cell kept: the map aims nothing");
    }
}

/// The default tracer, aiming photons by projection maps or not.
fn aiming(gpu: &photonmap::gpu::Gpu, projection_maps: bool) -> PhotonTracer {
    let config = TraceConfig {
        projection_maps,
        ..TraceConfig::default()
    };
    PhotonTracer::with_config(gpu, config).unwrap()
}

/// RING stores caustics only (scenes/ring.toml says so) because that loses
/// nothing: its only diffuse surface is a plane, and a vertical mirror keeps a
/// photon's vertical direction, so light that left the floor never returns to
/// it. Traced with the same random numbers, with and without the declaration
/// (and without projection maps, which draw other numbers), the stored
/// photons are the same records.
#[test]
fn ring_loses_no_stored_photon_by_storing_caustics_only() {
    let gpu = common::gpu();
    let mut all_paths = common::paper_scene("ring");
    all_paths.photon_map.caustics_only = false;
    let mut caustics = all_paths.clone();
    caustics.photon_map.caustics_only = true;
    let textures = SceneTextures::new(&gpu, &all_paths).unwrap();
    let tracer = aiming(&gpu, false);
    let stored = |scene: &Scene| -> Vec<PhotonRecord> {
        let frames = tracer.trace(scene, &textures, 5, 200_000).unwrap();
        records(&frames)
            .into_iter()
            .filter(|r| r.power.w != 0.0)
            .collect()
    };
    let (a, b) = (stored(&all_paths), stored(&caustics));
    eprintln!(
        "ring: {} stored with all paths, {} caustics only",
        a.len(),
        b.len()
    );
    assert!(
        a.len() > 1000,
        "too few stored photons ({}) to compare",
        a.len()
    );
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.position, x.power), (y.position, y.power));
    }
}

/// Projection maps change where photons go, not the light they carry: the
/// caustic flux stored with them equals the flux stored by photons emitted in
/// every direction, within 4 standard errors of the difference (each photon's
/// stored power is one sample; the error is the sample deviation / sqrt(N)).
#[test]
fn projection_maps_keep_the_stored_caustic_flux() {
    let gpu = common::gpu();
    for name in ["glass_ball", "cornell_box", "ring"] {
        let mut scene = common::paper_scene(name);
        scene.photon_map.caustics_only = true;
        let textures = SceneTextures::new(&gpu, &scene).unwrap();
        let flux = |aimed: bool, emitted: u32| -> (f64, f64) {
            let tracer = aiming(&gpu, aimed);
            let frames = tracer.trace(&scene, &textures, 3, emitted).unwrap();
            assert_eq!(frames.projection.is_some(), aimed);
            let per_frame = (frames.width * frames.frame_height) as usize;
            let mut per_photon = vec![0f64; emitted as usize];
            for (texel, r) in records(&frames).iter().enumerate() {
                let photon = texel % per_frame;
                if r.power.w != 0.0 && photon < per_photon.len() {
                    per_photon[photon] += r.power.truncate().element_sum() as f64;
                }
            }
            let n = per_photon.len() as f64;
            let total: f64 = per_photon.iter().sum();
            let mean = total / n;
            let var = per_photon.iter().map(|y| (y - mean).powi(2)).sum::<f64>() / (n - 1.0);
            (total, var * n) // the total and its variance
        };
        let (everywhere, v1) = flux(false, 400_000);
        let (aimed, v2) = flux(true, 100_000);
        let z = (aimed - everywhere) / (v1 + v2).sqrt();
        eprintln!(
            "{name}: stored caustic flux {everywhere:.4} +- {:.4} emitting everywhere, {aimed:.4} +- {:.4} aimed (z = {z:.2})",
            v1.sqrt(),
            v2.sqrt()
        );
        assert!(z.abs() < 4.0, "{name}: aimed photons store {aimed}, photons emitted everywhere {everywhere} (z = {z})");
        // Aiming must also pay: per photon emitted, the flux varies less (each
        // photon carries 1/N of the power, so the total's variance is c / N).
        let per_photon = (v2 * 100_000.0) / (v1 * 400_000.0);
        eprintln!("{name}: variance per photon aimed / everywhere = {per_photon:.3}");
        assert!(
            per_photon < 1.0,
            "{name}: aiming did not lower the flux's variance per photon ({per_photon})"
        );
    }
}

/// A caustics-only scene whose light cannot face its mirror (the mirror sits
/// behind a one-sided area light) is refused with a reason, not traced forever.
#[test]
fn caustics_only_with_no_reachable_mirror_is_refused() {
    let scene = common::fixture("mirror_behind_light");
    let gpu = common::gpu();
    let textures = SceneTextures::new(&gpu, &scene).unwrap();
    let tracer = PhotonTracer::new(&gpu).unwrap();
    let err = match tracer.trace_to_stored(&scene, &textures, 1) {
        Ok(_) => panic!("a mirror no photon can reach was accepted"),
        Err(e) => {
            assert!(matches!(e, photonmap::Error::NoCausticPath), "{e}");
            e.to_string()
        }
    };
    assert!(
        err.contains("no light can send a photon towards a mirror or glass shape"),
        "{err}"
    );
}

/// The fused trace (every bounce of a photon in one pass) against the pass
/// per bounce: the same functions and random streams, so the same stored
/// records to float rounding, the same frames read, and nothing left over
/// from an earlier trace into the same batch (SPPM traces one batch anew
/// every iteration; the second seed here is traced after the first).
#[test]
fn the_fused_trace_stores_the_same_photons_as_the_pass_per_bounce() {
    let gpu = common::gpu();
    // Every photon path (SPPM's), and the paper's caustics only through
    // projection maps (RING, with the random-number texture).
    for (name, random, caustics_only) in [
        ("cornell_box", RandomSource::Hash, false),
        ("glass_ball", RandomSource::Hash, false),
        ("ring", RandomSource::Texture, true),
        ("obj", RandomSource::Hash, false),
    ] {
        let mut scene = match name {
            "obj" => obj_scene(),
            _ => common::paper_scene(name),
        };
        scene.photon_map.max_bounces = 16;
        scene.photon_map.caustics_only = caustics_only;
        let textures = SceneTextures::new(&gpu, &scene).unwrap();
        let traced = |fused: bool| {
            let config = TraceConfig {
                random,
                fused,
                ..TraceConfig::default()
            };
            let tracer = PhotonTracer::with_config(&gpu, config).unwrap();
            let mut batch = tracer.batch(&scene, 6000).unwrap();
            let mut out = Vec::new();
            for seed in [5, 6] {
                tracer
                    .trace_batch(&scene, &textures, &mut batch, seed)
                    .unwrap();
                let f = &batch.frames;
                let used = (f.width * f.frame_height * f.frames) as usize;
                out.push((f.frames, records(f)[..used].to_vec()));
            }
            out
        };
        let (passes, fused) = (traced(false), traced(true));
        let size = scene.size();
        for ((frames_p, p), (frames_f, f)) in passes.iter().zip(&fused) {
            assert_eq!(frames_p, frames_f, "{name}: frames read");
            let (mut stored, mut differ) = (0, 0);
            for (a, b) in p.iter().zip(f) {
                assert_eq!(a.power.w, b.power.w, "{name}: a record stored by one only");
                if a.power.w == 0.0 {
                    continue;
                }
                stored += 1;
                let power = a.power.truncate().abs().max_element().max(1e-20);
                if !close(a.position, b.position, size) || !close(a.power, b.power, power) {
                    differ += 1;
                }
            }
            eprintln!("{name}: {stored} stored records, {differ} differ beyond 1e-4");
            assert!(stored > 300, "{name}: only {stored} stored records");
            assert_eq!(
                differ, 0,
                "{name}: {differ} of {stored} stored records differ"
            );
        }
    }
}
