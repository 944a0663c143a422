//! The photon-map builds against plain-Rust twins on the same inputs: bitonic
//! sort vs a CPU sort, binary search vs a CPU lower bound, stencil routing vs a
//! CPU simulation of the same draw order.

use crate::common;

use crate::common::Rng;

use photonmap::gpu::{Gpu, TexFormat, Texture};
use photonmap::photon::bitonic::{
    fused_plan, key_records, pass_count, sorted_pairs, BitonicBuild, INVALID_KEY,
};
use photonmap::photon::compaction::sort_texture_size;
use photonmap::photon::{
    Grid, GridStorage, PhotonFrames, PhotonTracer, SortedPhotonMap, StencilRouting, VertexFeed,
};
use photonmap::render::Timings;
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::Scene;
use photonmap::twins::photon::route;

/// Sorts on the GPU in RG32I (what the build uses) or RGBA32I.
fn sort_on_gpu(
    gpu: &Gpu,
    build: &BitonicBuild,
    keys: &[i32],
    format: TexFormat,
) -> (Vec<(i32, i32)>, u32) {
    let (w, h) = sort_texture_size(keys.len() as u64);
    assert_eq!((w * h) as usize, keys.len());
    let channels = format.channels();
    let data: Vec<i32> = keys
        .iter()
        .enumerate()
        .flat_map(|(i, &k)| [k, i as i32, 0, 0].into_iter().take(channels))
        .collect();
    let tex = Texture::from_texels(gpu, w, h, format, &data).unwrap();
    let (sorted, passes) = build.sort(tex).unwrap();
    (
        sorted
            .read_i32()
            .chunks(channels)
            .map(|c| (c[0], c[1]))
            .collect(),
        passes,
    )
}

/// Both sorts, the faithful passes (one a step) and the fused ones (two
/// long steps a pass, the short ones in registers), give the CPU's order.
#[test]
fn bitonic_sort_equals_a_cpu_sort_for_every_power_of_two_to_2_pow_16() {
    let gpu = common::gpu();
    let faithful = BitonicBuild::new(&gpu).unwrap().fusing(false);
    let fused = BitonicBuild::new(&gpu).unwrap().fusing(true);
    let mut rng = Rng(0xC0FFEE);
    for k in 1..=16u32 {
        let n = 1usize << k;
        let patterns: Vec<(&str, Vec<i32>)> = vec![
            (
                "random with duplicates",
                (0..n)
                    .map(|_| (rng.next_u64() % (n as u64 / 4 + 1)) as i32)
                    .collect(),
            ),
            ("all equal", vec![7; n]),
            ("sorted", (0..n as i32).collect()),
            ("reversed", (0..n as i32).rev().collect()),
            (
                "a third invalid",
                (0..n)
                    .map(|i| {
                        if i % 3 == 0 {
                            INVALID_KEY
                        } else {
                            (rng.next_u64() % 1000) as i32
                        }
                    })
                    .collect(),
            ),
        ];
        for (name, keys) in patterns {
            let format = if k % 2 == 0 {
                TexFormat::Rg32I
            } else {
                TexFormat::Rgba32I
            };
            let cpu = sorted_pairs(&keys);
            let (gpu_sorted, passes) = sort_on_gpu(&gpu, &faithful, &keys, format);
            assert_eq!(passes, pass_count(n as u64), "n = {n}");
            assert_eq!(
                gpu_sorted, cpu,
                "n = {n}, {name}: GPU order differs from the CPU sort"
            );
            let (fused_sorted, fused_passes) = sort_on_gpu(&gpu, &fused, &keys, format);
            let width = sort_texture_size(n as u64).0;
            assert_eq!(fused_passes as usize, fused_plan(n as u64, width).len());
            assert_eq!(
                fused_sorted, cpu,
                "n = {n}, {name}: the fused sort's order differs from the CPU sort"
            );
        }
    }
    assert_eq!(
        pass_count(1 << 20),
        210,
        "the paper's 210 passes for 1024 x 1024"
    );
    // One local pass (blocks of SORT_BLOCK = 2), then for stages 4..2^20
    // the long steps two a pass and one local pass each:
    // 1 + sum over s = 2..20 of ceil((s - 1) / 2) + 1.
    assert_eq!(fused_plan(1 << 20, 1024).len(), 120);
}

#[test]
fn binary_search_equals_a_cpu_lower_bound_with_empty_cells() {
    let gpu = common::gpu();
    let build = BitonicBuild::new(&gpu).unwrap();
    let mut rng = Rng(42);
    for (n, cells) in [(1024usize, 50u32), (4096, 4000), (1 << 14, 7)] {
        // Sparse keys: most cells empty in the second case, invalid keys at the end.
        let keys: Vec<i32> = (0..n)
            .map(|i| {
                if i % 5 == 0 {
                    INVALID_KEY
                } else {
                    (rng.next_u64() % cells as u64) as i32
                }
            })
            .collect();
        let (sorted, _) = {
            let (w, h) = sort_texture_size(n as u64);
            let data: Vec<i32> = keys
                .iter()
                .enumerate()
                .flat_map(|(i, &k)| [k, i as i32, 0, 0])
                .collect();
            build
                .sort(Texture::from_i32(&gpu, w, h, &data).unwrap())
                .unwrap()
        };
        let sorted_keys: Vec<i32> = sorted.read_i32().chunks(4).map(|c| c[0]).collect();
        let (first, grid_width) = build.binary_search(&sorted, cells).unwrap();
        let first: Vec<i32> = first.read_i32().chunks(4).map(|c| c[0]).collect();
        let mut empty = 0;
        for c in 0..=cells {
            let expect = sorted_keys.partition_point(|&k| k < c as i32) as i32;
            assert_eq!(
                first[c as usize], expect,
                "cell {c} of {cells} (grid width {grid_width})"
            );
            if c < cells && sorted_keys.partition_point(|&k| k < c as i32 + 1) as i32 == expect {
                empty += 1;
            }
        }
        // The sentinel past the last cell counts the valid photons.
        assert_eq!(
            first[cells as usize] as usize,
            keys.iter().filter(|&&k| k != INVALID_KEY).count()
        );
        if cells == 4000 {
            assert!(empty > 1000, "the test needs empty cells ({empty})");
        }
    }
}

fn check_routing(gpu: &Gpu, points: &[[f32; 3]], grid: &Grid, block: u32, feed: VertexFeed) {
    let frames = common::frames_from_points(gpu, points, |i| [1.0 + (i % 7) as f32, 2.0, 0.5]);
    let routing = StencilRouting::new(gpu).unwrap();
    let map = routing
        .build(&frames, grid, block, feed, &mut Timings::default())
        .unwrap();
    let cells: Vec<Option<u32>> = points
        .iter()
        .map(|p| grid.cell_of(glam::Vec3::from(*p)))
        .collect();
    let (stored, destined) = route(&cells, grid.cell_count(), block);

    let counts = map.counts.read_f32();
    for c in 0..grid.cell_count() as usize {
        assert_eq!(
            counts[4 * c] as u32,
            destined[c],
            "destined count of cell {c}"
        );
    }
    let position = map.position.read_f32();
    let power = map.power.read_f32();
    let w = map.position.width as usize;
    let m = block as usize;
    let (mut total_destined_power, mut total_stored_power) = (0f64, 0f64);
    for (i, p) in points.iter().enumerate() {
        if cells[i].is_some() {
            total_destined_power += (1.0 + (i % 7) as f64) + 2.0 + 0.5;
        }
        let _ = p;
    }
    for c in 0..grid.cell_count() as usize {
        let (bx, by) = (
            c % map.blocks_per_row as usize,
            c / map.blocks_per_row as usize,
        );
        for s in 0..m * m {
            let texel = (by * m + s / m) * w + bx * m + s % m;
            // The k-th photon of the cell lands in slot m^2 - 1 - k.
            let k = m * m - 1 - s;
            match stored[c].get(k) {
                Some(&record) => {
                    let expect = points[record];
                    assert_eq!(
                        &position[4 * texel..4 * texel + 3],
                        &expect,
                        "cell {c} slot {s}"
                    );
                    assert_eq!(position[4 * texel + 3], 1.0);
                    let ratio = destined[c] as f32 / stored[c].len() as f32;
                    let expect_power = [
                        (1.0 + (record % 7) as f32) * ratio,
                        2.0 * ratio,
                        0.5 * ratio,
                    ];
                    for ch in 0..3 {
                        let got = power[4 * texel + ch];
                        assert!(
                            (got - expect_power[ch]).abs() <= 1e-6 * expect_power[ch],
                            "cell {c} slot {s}: power {got} vs {}",
                            expect_power[ch]
                        );
                        total_stored_power += got as f64;
                    }
                }
                None => assert_eq!(
                    position[4 * texel + 3],
                    0.0,
                    "cell {c} slot {s} should be empty"
                ),
            }
        }
    }
    // Power is conserved only where every photon of a cell has the same power; in
    // general redistribution keeps the count ratio, so compare against that.
    let mut expect_total = 0f64;
    for c in 0..grid.cell_count() as usize {
        let ratio = destined[c] as f64 / stored[c].len().max(1) as f64;
        expect_total += stored[c]
            .iter()
            .map(|&r| ((1.0 + (r % 7) as f64) + 2.5) * ratio)
            .sum::<f64>();
    }
    assert!(
        (total_stored_power - expect_total).abs() <= 1e-5 * expect_total,
        "{total_stored_power} vs {expect_total}"
    );
    let _ = total_destined_power;
}

/// A uniform grid of `resolution` cells over the unit cube.
fn unit_grid(resolution: [u32; 3]) -> Grid {
    Grid {
        min: glam::Vec3::ZERO,
        max: glam::Vec3::ONE,
        resolution,
        storage: GridStorage::Uniform,
    }
}

#[test]
fn stencil_routing_equals_a_cpu_simulation_of_the_draw_order() {
    let gpu = common::gpu();
    let grid = unit_grid([5, 4, 3]);
    let mut rng = Rng(7);
    let mut points: Vec<[f32; 3]> = (0..3000)
        .map(|_| {
            let u = |r: &mut Rng| (r.next_u64() % 100_000) as f32 / 100_000.0;
            [u(&mut rng), u(&mut rng) * 0.5, u(&mut rng)]
        })
        .collect();
    points.push([2.0, 2.0, 2.0]); // outside the grid: never drawn
    for feed in [VertexFeed::VertexFetch, VertexFeed::Readback] {
        for block in [4, 16] {
            check_routing(&gpu, &points, &grid, block, feed);
        }
    }
}

#[test]
fn stencil_routing_counts_past_255_and_never_overwrites() {
    let gpu = common::gpu();
    let grid = unit_grid([2, 1, 1]);
    // 300 photons into cell 0 and 5 into cell 1, at distinct points.
    let mut points: Vec<[f32; 3]> = (0..300)
        .map(|i| [0.1 + 0.001 * i as f32, 0.5, 0.5])
        .collect();
    points.extend((0..5).map(|i| [0.9 - 0.01 * i as f32, 0.5, 0.5]));
    for block in [16, 4] {
        check_routing(&gpu, &points, &grid, block, VertexFeed::VertexFetch);
    }
    // All photons in one cell, m = 16: the first 256 kept, the stencil saturated.
    let one: Vec<[f32; 3]> = (0..600)
        .map(|i| [0.2 + 0.0001 * i as f32, 0.5, 0.5])
        .collect();
    check_routing(
        &gpu,
        &one,
        &unit_grid([1, 1, 1]),
        16,
        VertexFeed::VertexFetch,
    );
}

#[test]
fn routed_power_equals_destined_power_when_photons_are_alike() {
    // Equal-power photons, cells far over capacity: redistribution must conserve
    // the total exactly (up to float rounding).
    let gpu = common::gpu();
    let grid = unit_grid([3, 1, 2]);
    let mut rng = Rng(99);
    let points: Vec<[f32; 3]> = (0..5000)
        .map(|_| {
            [
                (rng.next_u64() % 1000) as f32 / 1000.0,
                0.5,
                (rng.next_u64() % 1000) as f32 / 1000.0,
            ]
        })
        .collect();
    let frames = common::frames_from_points(&gpu, &points, |_| [0.25, 0.5, 1.0]);
    for block in [4u32, 16] {
        let map = StencilRouting::new(&gpu)
            .unwrap()
            .build(
                &frames,
                &grid,
                block,
                VertexFeed::VertexFetch,
                &mut Timings::default(),
            )
            .unwrap();
        let stored: f64 = map
            .power
            .read_f32()
            .chunks(4)
            .map(|p| (p[0] + p[1] + p[2]) as f64)
            .sum();
        let destined = points.len() as f64 * 1.75;
        assert!(
            (stored - destined).abs() <= 1e-5 * destined,
            "m = {block}: stored power {stored}, destined {destined}"
        );
    }
}

#[test]
fn the_stencil_pattern_and_saturation_are_as_the_paper_describes() {
    // Read the stencil after routing 300 photons into one 16 x 16 cell: every
    // slot has counted min(255, slot + 300) = 255; with 10 photons, slot + 10.
    let gpu = common::gpu();
    let grid = unit_grid([1, 1, 1]);
    for n in [10usize, 300] {
        let points: Vec<[f32; 3]> = (0..n).map(|i| [0.001 * i as f32, 0.5, 0.5]).collect();
        let frames = common::frames_from_points(&gpu, &points, |_| [1.0; 3]);
        let routing = StencilRouting::new(&gpu).unwrap();
        let (stencil, _) = routing.build_for_stencil_test(&frames, &grid, 16).unwrap();
        for (s, &v) in stencil.iter().enumerate() {
            let slot = (s / 16) * 16 + s % 16;
            assert_eq!(
                v as usize,
                (slot + n).min(255),
                "slot {slot} after {n} photons"
            );
        }
    }
}

/// CORNELL BOX and its photons traced to the stored count with `seed`.
fn cornell_box_photons(gpu: &Gpu, seed: u32) -> (Scene, PhotonFrames) {
    let scene = common::paper_scene("cornell_box");
    let textures = SceneTextures::new(gpu, &scene).unwrap();
    let (frames, _) = PhotonTracer::new(gpu)
        .unwrap()
        .trace_to_stored(&scene, &textures, seed)
        .unwrap();
    (scene, frames)
}

/// A sorted map's cell table, entries 0..=slots.
fn cell_table(m: &SortedPhotonMap, slots: u32) -> Vec<i32> {
    let all: Vec<i32> = m.grid_first.read_i32().chunks(4).map(|c| c[0]).collect();
    all[..=slots as usize].to_vec()
}

/// A sorted map's (slot, record) pairs, every texel.
fn sorted_pairs_of(m: &SortedPhotonMap) -> Vec<(i32, i32)> {
    m.pairs.read_i32().chunks(2).map(|c| (c[0], c[1])).collect()
}

#[test]
fn compaction_gives_the_same_map_as_sorting_every_record() {
    let gpu = common::gpu();
    let (scene, frames) = cornell_box_photons(&gpu, 2);
    let grid = Grid::for_scene(&scene);
    let build = BitonicBuild::new(&gpu).unwrap();
    let compacted = build
        .build(&frames, &grid, &mut Timings::default())
        .unwrap();
    let build = build.compacting(false);
    let full = build
        .build(&frames, &grid, &mut Timings::default())
        .unwrap();
    let first = |m: &SortedPhotonMap| cell_table(m, grid.slot_count());
    assert_eq!(first(&compacted), first(&full), "cell ranges differ");
    let valid = first(&full)[grid.cell_count() as usize] as usize;
    assert!(valid > 60_000, "{valid} photons in the map");
    let pairs = |m: &SortedPhotonMap| sorted_pairs_of(m)[..valid].to_vec();
    assert_eq!(
        pairs(&compacted),
        pairs(&full),
        "sorted (cell, record) pairs differ"
    );
    assert!(
        compacted.pairs.width * compacted.pairs.height < full.pairs.width * full.pairs.height / 4
    );
}

#[test]
fn float_addressing_refuses_sorts_past_2_pow_24() {
    let gpu = common::gpu();
    let build = BitonicBuild::with_addressing(&gpu, true).unwrap();
    // 2^25 pairs: float indices would no longer be exact.
    let big = Texture::new(&gpu, 8192, 4096, TexFormat::Rg32I).unwrap();
    let err = build.sort(big).err().expect("must refuse");
    assert!(
        matches!(err, photonmap::Error::FloatAddressLimit { texels, .. } if texels == 1 << 25),
        "{err}"
    );
    let err = err.to_string();
    assert!(err.contains("2^24") && err.contains("--faithful"), "{err}");
    // Below the limit it sorts like the integer version.
    let keys: Vec<i32> = (0..4096).map(|i| i * 7919 % 1000).collect();
    let (w, h) = sort_texture_size(keys.len() as u64);
    let data = key_records(&keys);
    let (sorted, _) = build
        .sort(Texture::from_texels(&gpu, w, h, TexFormat::Rg32I, &data).unwrap())
        .unwrap();
    let got: Vec<(i32, i32)> = sorted.read_i32().chunks(2).map(|c| (c[0], c[1])).collect();
    let cpu = sorted_pairs(&keys);
    assert_eq!(got, cpu);
}

/// The counting build against the bitonic build (itself tested against a
/// CPU sort above) and against the twin's order (`sorted_pairs` over each
/// photon's slot): the same cell table, and in each slot the same photons.
/// On llvmpipe, whose tiles shade their fragments in draw order, each slot's
/// photons also lie in record order, so the maps are equal bit for bit.
/// Cases: CORNELL BOX's traced photons (several frames, unstored records) in
/// its uniform grid and in a hash table, and synthetic photons crowding one
/// cell, others spread, some outside the grid.
#[test]
fn the_counting_build_gives_the_bitonic_builds_map() {
    use photonmap::photon::CountingBuild;
    let gpu = common::gpu();
    let in_draw_order = gpu.capabilities().gl_renderer.contains("llvmpipe");
    let bitonic = BitonicBuild::new(&gpu).unwrap();
    let counting = CountingBuild::new(&gpu).unwrap();
    let (scene, traced) = cornell_box_photons(&gpu, 3);
    let mut rng = Rng(0xB0C5);
    let mut points: Vec<[f32; 3]> = (0..5000)
        .map(|i| match i % 5 {
            0 | 1 => [0.51, 0.52, 0.53], // one crowded cell
            2 => [1.5, 0.5, 0.5],        // outside the grid
            _ => [rng.f64() as f32, rng.f64() as f32, rng.f64() as f32],
        })
        .collect();
    points.push([1.0, 1.0, 1.0]); // on the max faces: the last cell
    let synthetic = common::frames_from_points(&gpu, &points, |_| [1.0; 3]);
    let unit = unit_grid([16, 8, 4]);
    let cases = [
        (
            "CORNELL BOX, uniform grid",
            &traced,
            Grid::for_scene(&scene),
        ),
        (
            "CORNELL BOX, 4096 hash buckets",
            &traced,
            Grid::for_scene(&scene).with_storage(GridStorage::Hashed { buckets: 4096 }),
        ),
        ("crowded cell, uniform grid", &synthetic, unit),
        (
            "crowded cell, 100 hash buckets",
            &synthetic,
            unit.with_storage(GridStorage::Hashed { buckets: 100 }),
        ),
    ];
    for (name, frames, grid) in cases {
        let a = bitonic
            .build(frames, &grid, &mut Timings::default())
            .unwrap();
        let b = counting
            .build(frames, &grid, &mut Timings::default())
            .unwrap();
        let (fa, fb) = (
            cell_table(&a, grid.slot_count()),
            cell_table(&b, grid.slot_count()),
        );
        assert_eq!(fa, fb, "{name}: the cell tables differ");
        let valid = fb[grid.slot_count() as usize] as usize;
        let pairs = |m: &SortedPhotonMap| {
            let all = sorted_pairs_of(m);
            assert!(
                all[valid..].iter().all(|p| p.0 == INVALID_KEY),
                "{name}: a pair past the {valid} photons is not the invalid key"
            );
            all[..valid].to_vec()
        };
        let (pa, pb) = (pairs(&a), pairs(&b));
        if name.starts_with("crowded") {
            // The twin: every point's slot, sorted on the CPU.
            let keys: Vec<i32> = points
                .iter()
                .map(|&p| match grid.cell_of(glam::Vec3::from(p)) {
                    Some(c) => grid.slot_of_cell(c) as i32,
                    None => INVALID_KEY,
                })
                .collect();
            let expected: Vec<(i32, i32)> = sorted_pairs(&keys)
                .into_iter()
                .filter(|p| p.0 != INVALID_KEY)
                .collect();
            assert_eq!(
                pa, expected,
                "{name}: the bitonic build is not the twin's order"
            );
            assert!(valid == points.len() - 1000, "{name}: {valid} photons kept");
        }
        let mut sorted_within = pb.clone();
        sorted_within.sort_unstable();
        assert_eq!(pa, sorted_within, "{name}: a slot holds other photons");
        if in_draw_order {
            assert_eq!(pa, pb, "{name}: not in record order within a slot");
            let texels = |t: &Texture| t.read_f32()[..4 * valid].to_vec();
            for (x, y) in [
                (&a.position, &b.position),
                (&a.power, &b.power),
                (&a.incoming, &b.incoming),
            ] {
                assert!(
                    texels(x)
                        .iter()
                        .zip(texels(y))
                        .all(|(p, q)| p.to_bits() == q.to_bits()),
                    "{name}: the sorted records differ"
                );
            }
        }
        eprintln!(
            "{name}: {valid} photons, {} slots: the same map",
            grid.slot_count()
        );
    }
}
