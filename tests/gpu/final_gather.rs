//! Final gather (section 4.5): the gather rays and the per-pixel sum of the
//! global map's estimates at their hits equal the CPU twin on the same
//! photons, and the method converges to an analytic answer.

use crate::common;

use glam::Vec3;
use photonmap::photon::PhotonConfig;
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::software::CpuPhotonMap;
use photonmap::render::{
    render, DirectLight, EstimateOptions, FinalGather, FinalGatherOptions, Method,
    PhotonMapOptions, RenderOptions,
};
use photonmap::scene::{Material, Scene};
use photonmap::twins::final_gather::{gather_ray, gathered_radiance, GatherHit};

fn gather_options(scene: &Scene, w: u32, h: u32, seed: u32, rays: u32, k: u32) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (w, h, seed);
    o.method = Method::PhotonMap(PhotonMapOptions {
        photons: PhotonConfig::default(),
        estimate: EstimateOptions {
            leak: LeakTest::None,
            ..EstimateOptions::default()
        },
        final_gather: Some(FinalGatherOptions {
            rays,
            k,
            leak: LeakTest::None,
        }),
        adaptive: None,
    });
    o
}

/// One batch holds all 8 rays of each pixel, so the gather textures hold
/// every ray after the render: each is compared with the CPU's ray from the
/// same first hit and random numbers, and each pixel's indirect light with the
/// CPU kNN-grid's estimates at the GPU's hits on the same global map. A ray
/// may end elsewhere only where the two tracers' rounding sends it past an edge.
#[test]
fn final_gather_equals_its_cpu_twin() {
    let c = gather_against_twin(&common::fixture("mirror_box"));
    let TwinCheck {
        rays_checked,
        rays_apart,
        through_specular,
        pixels,
        pixels_apart,
    } = c;
    eprintln!(
        "final gather twin: {rays_apart} of {rays_checked} rays apart ({through_specular} through mirror or glass), {pixels_apart} of {pixels} pixels apart"
    );
    assert!(through_specular > 50, "the scene exercises specular chains");
    assert!(rays_apart * 200 <= rays_checked, "{rays_apart} rays apart");
    assert!(pixels_apart * 100 <= pixels, "{pixels_apart} pixels apart");
}

/// The same through metals (`scenes/tests/metal_box.toml`): a gather ray
/// that meets the rough gold sphere goes on along a sample of its lobe, and
/// one that meets the smooth aluminium sphere takes its Fresnel, as the twin
/// does with the same random numbers.
#[test]
fn final_gather_through_metals_equals_its_cpu_twin() {
    let c = gather_against_twin(&common::paper_scene("tests/metal_box"));
    eprintln!(
        "final gather twin through metals: {} of {} rays apart ({} through a metal), {} of {} pixels apart",
        c.rays_apart, c.rays_checked, c.through_specular, c.pixels_apart, c.pixels
    );
    assert!(c.through_specular > 50, "the scene exercises the metals");
    assert!(
        c.rays_apart * 200 <= c.rays_checked,
        "{} rays apart",
        c.rays_apart
    );
    assert!(
        c.pixels_apart * 100 <= c.pixels,
        "{} pixels apart",
        c.pixels_apart
    );
}

/// `scene` by final gather at 24 x 24 (8 rays a pixel in one batch, k 40,
/// seed 5), every ray and pixel against the twin (`compare_with_twin`).
fn gather_against_twin(scene: &Scene) -> TwinCheck {
    let gpu = common::gpu();
    let (w, h, rays, k, seed) = (24u32, 24u32, 8u32, 40u32, 5u32);
    let out = render(
        &gpu,
        scene,
        &gather_options(scene, w, h, seed, rays, k),
        &mut (),
    )
    .unwrap();
    let fg = out.gather().unwrap();
    assert_eq!(fg.rays.batch, rays, "one batch holds every ray");
    let map = CpuPhotonMap::from_gpu(out.gather_map().unwrap());
    let depth_and_fade = (scene.render.max_specular_depth, 0.0);
    compare_with_twin(
        scene,
        &out.state.direct,
        fg,
        &map,
        (seed, rays, k),
        depth_and_fade,
    )
}

/// What `compare_with_twin` counted.
pub struct TwinCheck {
    pub rays_checked: u32,
    pub rays_apart: u32,
    /// GPU rays whose hit came through a mirror or glass, or was weighted.
    pub through_specular: u32,
    pub pixels: u32,
    pub pixels_apart: u32,
}

/// Each gather ray of `fg` (one batch holding every ray) against the CPU's
/// ray from the same first hit and random numbers, and each pixel's indirect
/// light against the CPU kNN-grid's estimates at the GPU's hits on `map`.
pub fn compare_with_twin(
    scene: &Scene,
    direct: &DirectLight,
    fg: &FinalGather,
    map: &CpuPhotonMap,
    (seed, rays, k): (u32, u32, u32),
    (max_depth, fade): (u32, f32),
) -> TwinCheck {
    let common::FirstHits {
        width: w,
        height: h,
        position: first,
        normal: first_normal,
        throughput: first_throughput,
    } = common::first_hits(direct);
    let (gp, gn, gt) = (
        common::texels(&fg.rays.position),
        common::texels(&fg.rays.normal),
        common::texels(&fg.rays.throughput),
    );
    let indirect = common::texels(&fg.indirect);
    let max_radius = scene.photon_map.max_radius;
    let mut c = TwinCheck {
        rays_checked: 0,
        rays_apart: 0,
        through_specular: 0,
        pixels: 0,
        pixels_apart: 0,
    };
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if first[i][3] <= 0.0 {
                continue;
            }
            let mut sum = Vec3::ZERO;
            for j in 0..rays {
                let g = i + (j * w * h) as usize;
                let (p1, n1) = (common::v3(first[i]), common::v3(first_normal[i]));
                let cpu = gather_ray(scene, p1, n1, seed, [x, y], j, max_depth, fade);
                let gpu_hit = (gp[g][3] > 0.0).then(|| GatherHit {
                    position: common::v3(gp[g]),
                    normal: common::v3(gn[g]),
                    material: gn[g][3] as usize - 1,
                    throughput: common::v3(gt[g]),
                });
                c.rays_checked += 1;
                let same = match (&cpu, &gpu_hit) {
                    (None, None) => true,
                    (Some(a), Some(b)) => {
                        a.material == b.material
                            && a.position.distance(b.position) < 1e-3
                            && (a.throughput - b.throughput).abs().max_element() < 1e-4
                    }
                    _ => false,
                };
                if !same {
                    c.rays_apart += 1;
                }
                if let Some(hit) = gpu_hit {
                    if hit.throughput != Vec3::ONE {
                        c.through_specular += 1;
                    }
                    sum += gathered_radiance(scene, map, &hit, k, max_radius);
                }
            }
            let Material::Diffuse { albedo } = scene.materials[first_normal[i][3] as usize - 1]
            else {
                panic!("a first diffuse hit on a diffuse material");
            };
            let expected = common::v3(first_throughput[i]) * albedo * sum / rays as f32;
            let got = common::v3(indirect[i]);
            c.pixels += 1;
            if (got - expected).abs().max_element() > 1e-4 + 1e-3 * expected.max_element() {
                c.pixels_apart += 1;
            }
        }
    }
    c
}

/// The furnace: a closed diffuse sphere (albedo 1/2, radius 1) with a point
/// light of intensity 1 at its centre has L = rho I / (pi R^2 (1 - rho)) =
/// 1 / pi everywhere. Final gather takes the first bounce by shadow rays and
/// the rest from the global map at the gather rays' hits, which (by
/// Archimedes' hat-box theorem: a sphere's cap inside a ball of radius r has
/// area pi r^2) is unbiased on the sphere but for the k-nearest estimate's own
/// bias: with k photons in the disc whose edge the k-th one sets, its mean is
/// k / (k - 1) of the density, +2.0% at k = 50 on the gathered half of L,
/// so +1.0% at most on L. The two seeds' means differ by 0.03%.
#[test]
fn final_gather_in_the_furnace_is_analytic() {
    let gpu = common::gpu();
    let scene = common::fixture("furnace");
    let expected = 1.0 / std::f64::consts::PI;
    let means: Vec<f64> = (1..=2)
        .map(|seed| {
            let o = gather_options(&scene, 32, 32, seed, 32, 50);
            let out = render(&gpu, &scene, &o, &mut ()).unwrap();
            out.image.mean()[0]
        })
        .collect();
    for m in &means {
        eprintln!(
            "furnace, final gather: mean {m:.5} against {expected:.5} ({:+.3}%)",
            100.0 * (m / expected - 1.0)
        );
    }
    let mean = 0.5 * (means[0] + means[1]);
    assert!((mean / expected - 1.0).abs() < 0.01, "{mean} vs {expected}");
}
