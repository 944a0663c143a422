//! IGI's bias compensation: its gather rays and their sum over the global
//! map equal the CPU twin, and on a closed diffuse box whose geometry term
//! is bounded hard, the compensated render matches the independent CPU path
//! tracer where the bounded one falls short of it.

use crate::common;
use crate::final_gather::{compare_with_twin, TwinCheck};

use photonmap::render::software::CpuPhotonMap;
use photonmap::render::{render, IgiOptions, Method, RenderOptions, WithCausticMap};
use photonmap::scene::Scene;

fn options(scene: &Scene, (w, h): (u32, u32), seed: u32, igi: IgiOptions) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (w, h, seed);
    o.method = Method::Igi(WithCausticMap {
        method: igi,
        ..WithCausticMap::default()
    });
    o
}

/// One batch holds all 8 rays of each pixel: each is compared with the CPU's
/// ray from the same first hit and random numbers (a diffuse hit straight
/// from it, weighted by 1 - f(d), or nothing), and each pixel's compensation
/// with the CPU kNN-grid's estimates at the GPU's hits on the same map. In
/// the mirror box, rays also meet the mirrors and the glass ball, where they
/// must stop.
#[test]
fn the_compensation_rays_equal_their_cpu_twin() {
    let gpu = common::gpu();
    let scene = common::fixture("mirror_box");
    let (size, rays, seed) = ((24u32, 24u32), 8u32, 5u32);
    let igi = IgiOptions {
        vpl_paths: 32,
        bias_compensation: rays,
        ..IgiOptions::default()
    };
    let out = render(&gpu, &scene, &options(&scene, size, seed, igi), &mut ()).unwrap();
    let c = out.igi_run().unwrap().compensation.as_ref().unwrap();
    assert_eq!(c.gather.rays.batch, rays, "one batch holds every ray");
    let map = CpuPhotonMap::from_gpu(&c.map);
    let check = compare_with_twin(
        &scene,
        &out.state.direct,
        &c.gather,
        &map,
        (seed, rays, c.k()),
        (0, c.fade()),
    );
    let TwinCheck {
        rays_checked,
        rays_apart,
        through_specular: weighted,
        pixels,
        pixels_apart,
    } = check;
    let hits = c.stats[0].queries;
    eprintln!(
        "bias compensation twin: {rays_apart} of {rays_checked} rays apart, {hits} reached a diffuse surface within 1.2 m ({weighted} of them weighted below 1), {pixels_apart} of {pixels} pixels apart"
    );
    assert!(weighted > 50, "the scene exercises the fade: {weighted}");
    assert!(
        hits * 2 < rays_checked as u64,
        "most rays go past 1.2 m or meet a mirror: {hits} of {rays_checked}"
    );
    assert!(rays_apart * 200 <= rays_checked, "{rays_apart} rays apart");
    assert!(pixels_apart * 100 <= pixels, "{pixels_apart} pixels apart");
}

/// The two-light box (closed, diffuse, 1 x 1 x 1.5) with IGI's geometry term
/// bounded at m = 0.4, so that VPLs nearer than 0.48 give less and those
/// nearer than 0.32 nothing: against the CPU path tracer on the interior
/// blocks, the bounded render is darker by many standard deviations, and the
/// compensated one is within the bound the unbounded IGI test uses (chi^2/n
/// below 3), the global map's own kNN bias included (200,000 photons:
/// with the fixture's 10,000 and 4096 paths, chi^2/n was 2.9).
#[test]
fn compensated_igi_matches_the_path_tracer_where_the_bound_darkens_it() {
    let gpu = common::gpu();
    let mut scene = common::fixture("two_light_box");
    scene.photon_map.photons_stored = 200_000;
    let pt = photonmap::twins::path_trace::path_trace(&scene, 32, 32, 1024, 11);
    let run = |compensation: u32| {
        let runs: Vec<photonmap::render::Image> = [1u32, 2]
            .iter()
            .map(|&seed| {
                let igi = IgiOptions {
                    vpl_paths: 2048,
                    interleave: 1,
                    min_distance: Some(0.4),
                    bias_compensation: compensation,
                    ..IgiOptions::default()
                };
                let mut o = options(&scene, (32, 32), seed, igi);
                o.spp = 4;
                render(&gpu, &scene, &o, &mut ()).unwrap().image
            })
            .collect();
        common::blocks_against_path_tracer(&pt, [&runs[0], &runs[1]])
    };
    let (_, bounded_chi, bounded_worst) = run(0);
    let (_, chi, worst) = run(32);
    eprintln!(
        "two-light box, IGI bounded at 0.4: chi^2/n {bounded_chi:.2} (largest relative difference {:.1}%), compensated with 32 rays {chi:.2} ({:.1}%)",
        100.0 * bounded_worst,
        100.0 * worst
    );
    assert!(
        bounded_chi > 10.0,
        "the bound darkens the box: {bounded_chi}"
    );
    assert!(chi < 3.0, "compensated: chi^2/n = {chi}");
}
