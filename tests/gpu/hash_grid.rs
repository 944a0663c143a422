//! The hash grid of section 4.4: both builds keyed by the PCG hash of the
//! cell, against their CPU twins; a hashed render against the uniform one;
//! a 1024^3 grid that only the hash table can store.

use crate::common;

use glam::Vec3;
use photonmap::error::Error;
use photonmap::photon::{
    hash_bucket, BuildMethod, Grid, GridKind, GridStorage, PhotonConfig, PhotonMap, StencilRouting,
    VertexFeed,
};
use photonmap::render::{render, Method, PhotonMapOptions, RenderOptions, RenderOutput};
use photonmap::scene::Scene;
use photonmap::timing::Timings;
use photonmap::twins::knn::{knn_grid, CpuPhotonMap};
use photonmap::twins::photon::route_hashed;

fn render_with(
    scene: &Scene,
    (width, height): (u32, u32),
    photons: PhotonConfig,
) -> photonmap::gpu::Result<RenderOutput> {
    let gpu = common::gpu();
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (width, height, 3);
    let mut gi = PhotonMapOptions {
        photons,
        ..PhotonMapOptions::default()
    };
    gi.estimate.budget = 48;
    gi.estimate.leak = photonmap::render::radiance_estimate::LeakTest::None;
    o.method = Method::PhotonMap(gi);
    render(&gpu, scene, &o, &mut ())
}

fn config(build: BuildMethod, grid: GridKind, hash_buckets: Option<u32>) -> PhotonConfig {
    PhotonConfig {
        build,
        grid,
        hash_buckets,
        ..PhotonConfig::default()
    }
}

/// (query pixel, position, flux, r^2, accepted, photons examined) of every query.
fn queries(out: &RenderOutput) -> Vec<(usize, Vec3, Vec3, f32, u32, u64)> {
    let est = out.radiance_estimate().unwrap();
    let (flux, cursor, done) = (
        est.flux.read_f32(),
        est.cursor.read_i32(),
        est.done.read_i32(),
    );
    let pos = out.state.direct.diffuse_position.read_f32();
    (0..pos.len() / 4)
        .filter(|&i| pos[4 * i + 3] > 0.0)
        .map(|i| {
            assert_eq!(done[4 * i], 1, "pixel {i} never finished");
            let v = |d: &[f32]| Vec3::from_slice(&d[4 * i..4 * i + 3]);
            let examined = done[4 * i + 1] as u64;
            (
                i,
                v(&pos),
                v(&flux),
                flux[4 * i + 3],
                cursor[4 * i] as u32,
                examined,
            )
        })
        .collect()
}

#[test]
fn hashed_maps_and_knn_search_equal_the_cpu_twin() {
    let scene = common::paper_scene("glass_ball");
    let (k, max_r) = (scene.photon_map.k, scene.photon_map.max_radius);
    // 61 buckets for 5000 photons: every bucket is shared, the search rejects a lot.
    for build in [BuildMethod::Bitonic, BuildMethod::Stencil] {
        for buckets in [None, Some(61)] {
            let out =
                render_with(&scene, (48, 36), config(build, GridKind::Hash, buckets)).unwrap();
            let map = out.map().unwrap();
            assert!(map.grid().buckets().is_some());
            let cpu_map = CpuPhotonMap::from_gpu(map);
            let results = queries(&out);
            assert!(results.len() > 48 * 36 / 3);
            let mut mismatched = 0;
            for (i, x, flux, r2, accepted, _) in &results {
                let cpu = knn_grid(&cpu_map, *x, k, max_r);
                let same = cpu.accepted == *accepted
                    && (cpu.radius2 - r2).abs() <= 1e-5 * r2.max(1e-12)
                    && (cpu.flux - *flux).abs().max_element()
                        <= 1e-4 * cpu.flux.max_element().max(1e-20);
                if !same && mismatched < 3 {
                    eprintln!(
                        "{build:?} {buckets:?} pixel {i}: GPU {accepted} {r2} {flux}, CPU {cpu:?}"
                    );
                }
                mismatched += usize::from(!same);
            }
            assert!(
                mismatched * 1000 <= results.len(),
                "{build:?} {buckets:?}: {mismatched} of {} pixels differ",
                results.len()
            );
        }
    }
}

/// Bitonic: the hashed map sorts by (bucket, record), so each cell's photons
/// come in the same order (by record) as in the uniform map; the search
/// accepts the same photons in the same order and sums the same floats: the
/// image is bit-identical. Only the photons examined grow (the collisions;
/// the README's hash-grid table times them).
#[test]
fn a_hashed_bitonic_render_is_bit_identical_to_the_uniform_one() {
    // 97 buckets for GLASS BALL's 5000 photons: every bucket is shared. CORNELL
    // BOX (65000 photons, k = 500) takes the default 65536 buckets.
    for (name, buckets) in [("glass_ball", Some(97)), ("cornell_box", None)] {
        let scene = common::paper_scene(name);
        let uniform = render_with(
            &scene,
            (48, 36),
            config(BuildMethod::Bitonic, GridKind::Uniform, None),
        )
        .unwrap();
        let hashed = render_with(
            &scene,
            (48, 36),
            config(BuildMethod::Bitonic, GridKind::Hash, buckets),
        )
        .unwrap();
        assert_eq!(
            uniform.image.pixels, hashed.image.pixels,
            "{name}: images differ"
        );
    }
}

#[test]
fn a_1024_cubed_grid_renders_hashed_and_is_refused_uniform() {
    let mut scene = common::paper_scene("ring");
    scene.photon_map.grid_resolution = [1024, 1024, 1024];
    // A small radius keeps the search to a few shells of the fine cells.
    scene.photon_map.max_radius = 0.03;
    let err = render_with(
        &scene,
        (16, 12),
        config(BuildMethod::Bitonic, GridKind::Uniform, None),
    )
    .err()
    .expect("a uniform 1024^3 grid must be refused");
    let message = err.to_string();
    assert!(matches!(err, Error::InvalidOption(_)), "{message}");
    assert!(
        message.contains("--grid hash") && message.contains("134217728"),
        "{message}"
    );
    let out = render_with(
        &scene,
        (8, 6),
        config(BuildMethod::Bitonic, GridKind::Hash, None),
    )
    .unwrap();
    assert_eq!(out.map().unwrap().grid().resolution, [1024; 3]);
    assert!(out.image.pixels.iter().flatten().all(|v| v.is_finite()));
    assert!(out.image.pixels.iter().flatten().any(|&v| v > 0.0));
}

#[test]
fn hashed_stencil_routing_equals_its_twin_with_the_lost_power() {
    let gpu = common::gpu();
    let buckets = 7;
    let grid = Grid {
        min: Vec3::ZERO,
        max: Vec3::ONE,
        resolution: [5, 4, 3],
        storage: GridStorage::Hashed { buckets },
    };
    let mut rng = common::Rng(11);
    let points: Vec<[f32; 3]> = (0..600)
        .map(|_| std::array::from_fn(|_| (rng.next_u64() % 100_000) as f32 / 100_000.0))
        .collect();
    let raw = |i: usize| [1.0 + (i % 7) as f32, 2.0, 0.5];
    let frames = common::frames_from_points(&gpu, &points, |i| [1.0 + (i % 7) as f32, 2.0, 0.5]);
    let cells: Vec<Option<u32>> = points
        .iter()
        .map(|p| grid.cell_of(Vec3::from(*p)))
        .collect();
    for (block, feed) in [
        (4, VertexFeed::VertexFetch),
        (2, VertexFeed::Readback),
        (16, VertexFeed::VertexFetch),
    ] {
        let map = StencilRouting::new(&gpu)
            .unwrap()
            .build(&frames, &grid, block, feed, &mut Timings::default())
            .unwrap();
        let twin = route_hashed(&cells, buckets, block, &|c| hash_bucket(c, buckets));
        let counts = map.counts.read_f32();
        let (position, power) = (map.position.read_f32(), map.power.read_f32());
        let (w, m) = (map.position.width as usize, block as usize);
        let scale = frames.power_scale;
        for b in 0..buckets as usize {
            assert_eq!(counts[4 * b] as u32, twin.destined[b], "bucket {b}");
            let (bx, by) = (
                b % map.blocks_per_row as usize,
                b / map.blocks_per_row as usize,
            );
            for s in 0..m * m {
                let texel = (by * m + s / m) * w + bx * m + s % m;
                match twin.stored[b].get(m * m - 1 - s) {
                    Some(&r) => {
                        assert_eq!(
                            &position[4 * texel..4 * texel + 3],
                            &points[r],
                            "m {m} bucket {b} slot {s}"
                        );
                        for ch in 0..3 {
                            let expect = raw(r)[ch] * twin.scale[r] * scale;
                            let got = power[4 * texel + ch];
                            assert!(
                                (got - expect).abs() <= 1e-6 * expect,
                                "m {m} bucket {b} slot {s}: {got} vs {expect}"
                            );
                        }
                        assert_eq!(power[4 * texel + 3], twin.scale[r], "the photon's weight");
                    }
                    None => assert_eq!(
                        position[4 * texel + 3],
                        0.0,
                        "m {m} bucket {b} slot {s} empty"
                    ),
                }
            }
        }
        let lost = map.lost.expect("a hashed routing reports its lost power");
        assert_eq!(lost.photons, twin.lost.len() as u64, "m {m}");
        let expect: [f32; 3] =
            std::array::from_fn(|ch| twin.lost.iter().map(|&r| raw(r)[ch]).sum::<f32>() * scale);
        for ch in 0..3 {
            assert!(
                (lost.power[ch] - expect[ch]).abs() <= 1e-5 * expect[ch].max(1.0),
                "m {m}: {lost:?} vs {expect:?}"
            );
        }
        eprintln!(
            "m {m}: {} photons lost, {:.4} of the power",
            lost.photons,
            lost.fraction()
        );
        if m == 2 {
            assert!(
                lost.photons > 0,
                "7 buckets of 4 slots for 60 cells must lose cells"
            );
        }
        if m == 16 {
            assert_eq!(lost.photons, 0, "256 slots hold every bucket's cells");
        }
        let _ = PhotonMap::Routed(map);
    }
}
