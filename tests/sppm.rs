//! Stochastic progressive photon mapping: the gather-and-update kernel equals
//! its CPU twin, and the method converges to the exact answer, shown against
//! analytic scenes and against an independent CPU path tracer.

mod common;

use glam::Vec3;
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::reference::sppm::{update, PixelState, VisiblePoint};
use photonmap::render::software::CpuPhotonMap;
use photonmap::render::sppm::{render_sppm, Sppm, SppmOptions};
use photonmap::render::{GlobalIllumination, Image, RenderOptions};
use photonmap::scene::{load_scene_str, Material, Scene};
use photonmap::timing::Timings;

fn options(scene: &Scene, w: u32, h: u32, seed: u32, build: BuildMethod) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height, o.seed) = (w, h, seed);
    o.global = Some(GlobalIllumination {
        photons: PhotonConfig {
            build,
            ..PhotonConfig::default()
        },
        ..GlobalIllumination::default()
    });
    o
}

fn texels(t: &photonmap::gpu::Texture) -> Vec<[f32; 4]> {
    t.read_f32()
        .chunks(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

fn v3(t: [f32; 4]) -> Vec3 {
    Vec3::new(t[0], t[1], t[2])
}

/// After one iteration, the next one's GPU update against the twin run on the
/// same photons, visible points and state: counts agree exactly but where a
/// photon sits on the radius to rounding, flux and radius to float precision.
#[test]
fn the_gather_and_update_kernel_equals_its_cpu_twin() {
    let gpu = common::gpu();
    for (name, build) in [
        ("glass_ball", BuildMethod::Bitonic),
        ("cornell_box", BuildMethod::Stencil),
    ] {
        let scene = common::paper_scene(name);
        let sppm_options = SppmOptions {
            photons_per_iteration: 1 << 15,
            ..SppmOptions::default()
        };
        let mut run =
            Sppm::new(&gpu, &scene, &options(&scene, 64, 48, 5, build), &sppm_options).unwrap();
        let mut timings = Timings::default();
        run.iterate(&mut timings, &mut ()).unwrap();
        let (flux0, sums0) = (texels(&run.state.flux), texels(&run.state.sums));
        let first_radius2 = run.cell * run.cell;
        run.iterate(&mut timings, &mut ()).unwrap();
        let (flux1, sums1) = (texels(&run.state.flux), texels(&run.state.sums));
        let map = CpuPhotonMap::from_gpu(run.map.as_ref().unwrap());
        let d = &run.direct;
        let (direct, pos, normal, through) = (
            texels(&d.radiance),
            texels(&d.diffuse_position),
            texels(&d.diffuse_normal),
            texels(&d.diffuse_throughput),
        );
        let (mut gathering, mut count_differs, mut worst) = (0, 0, 0f32);
        for i in 0..flux0.len() {
            let mat = normal[i][3] as i32 - 1;
            let vp = (pos[i][3] > 0.0 && mat >= 0).then(|| {
                let Material::Diffuse { albedo } = run.scene().materials[mat as usize] else {
                    panic!("a visible point on a non-diffuse surface")
                };
                VisiblePoint {
                    position: v3(pos[i]),
                    normal: v3(normal[i]),
                    albedo,
                    throughput: v3(through[i]),
                }
            });
            let before = PixelState {
                tau: v3(flux0[i]),
                radius2: flux0[i][3],
                direct: v3(sums0[i]),
                count: sums0[i][3],
            };
            let cpu = update(&map, before, v3(direct[i]), vp, 0.7, first_radius2);
            if sums1[i][3] > sums0[i][3] {
                gathering += 1;
            }
            if cpu.count != sums1[i][3] {
                count_differs += 1;
                continue;
            }
            let rel = |a: f32, b: f32| (a - b).abs() / (a.abs().max(b.abs()) + 1e-6);
            for c in 0..3 {
                worst = worst.max(rel(cpu.tau[c], flux1[i][c]));
                worst = worst.max(rel(cpu.direct[c], sums1[i][c]));
            }
            worst = worst.max(rel(cpu.radius2, flux1[i][3]));
        }
        eprintln!(
            "{name} ({build:?}): {gathering} of {} pixels gathered photons; counts differ at {count_differs}; largest relative difference {worst:.2e}",
            flux0.len()
        );
        assert!(gathering > flux0.len() / 4, "{name}: too few pixels gathered");
        assert!(count_differs * 200 <= flux0.len(), "{name}: {count_differs} counts differ");
        assert!(worst < 1e-4, "{name}: {worst}");
    }
}
