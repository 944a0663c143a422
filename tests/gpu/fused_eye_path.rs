//! The fused eye path (`render/eye_path.frag`: a pixel's whole eye path in one
//! pass) against the paper's pass per bounce (eye rays, then per depth
//! intersect, shadow rays and specular): the same functions and random
//! streams, so the same radiance and the same first-diffuse-hit records, to
//! float rounding, in every paper scene and a mesh scene with vertex normals
//! and an emissive OBJ group, jittered, with several shadow rays.

use crate::common;

use photonmap::render::{trace_eye_paths, At, DirectLight, EyeSample, PassPlan, RayTracer};
use photonmap::render::{RenderOptions, Timings};
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::Scene;

/// The direct-light textures (radiance and the three records) of one eye
/// sample, traced fused or pass by pass.
fn eye_sample(scene: &Scene, fused: bool, width: u32, height: u32) -> Vec<Vec<[f32; 4]>> {
    let gpu = common::gpu();
    let options = RenderOptions {
        width,
        height,
        spp: 4,
        ..RenderOptions::for_scene(scene)
    };
    let mut plan = PassPlan::new(scene, &options);
    plan.fused = fused;
    plan.shadow_rays = 4;
    plan.shadow_batch = 2; // two batches a depth pass by pass: the sums' order differs
    plan.direct_passes = 2;
    let textures = SceneTextures::new(&gpu, scene).unwrap();
    let tracer = RayTracer::new(&gpu, width, height).unwrap();
    let direct = DirectLight::new(&gpu, width, height).unwrap();
    let eye = EyeSample {
        camera: &scene.camera,
        sample: 1,
        seed: 1234,
    };
    let at = At {
        view: 0,
        views: 1,
        sample: 1,
        samples: 4,
    };
    trace_eye_paths(
        &gpu,
        &plan,
        &textures,
        &tracer,
        &direct,
        &eye,
        &mut Timings::default(),
        &mut (),
        at,
    )
    .unwrap();
    [
        &direct.radiance,
        &direct.diffuse_position,
        &direct.diffuse_normal,
        &direct.diffuse_throughput,
    ]
    .iter()
    .map(|t| common::texels(t))
    .collect()
}

#[test]
fn fused_eye_path_equals_the_pass_per_bounce() {
    let mut scenes: Vec<Scene> = ["glass_ball", "ring", "cornell_box"]
        .iter()
        .map(|s| common::paper_scene(s))
        .collect();
    scenes.push(
        photonmap::scene::load_scene(&common::root().join("scenes/cornell_box_obj.toml")).unwrap(),
    );
    for scene in &scenes {
        let (w, h) = (96, 72);
        let passes = eye_sample(scene, false, w, h);
        let fused = eye_sample(scene, true, w, h);
        let names = ["radiance", "position", "normal", "throughput"];
        let mut lit = 0;
        for (t, name) in names.iter().enumerate() {
            let mut differing = 0;
            for (i, (a, b)) in passes[t].iter().zip(&fused[t]).enumerate() {
                let scale = a.iter().chain(b).fold(1e-3f32, |m, v| m.max(v.abs()));
                let worst = (0..4).map(|c| (a[c] - b[c]).abs()).fold(0f32, f32::max);
                if worst > 1e-4 * scale {
                    differing += 1;
                    if differing <= 3 {
                        eprintln!("{} {name} pixel {i}: {a:?} against {b:?}", scene.name);
                    }
                }
                if t == 0 && a[0] + a[1] + a[2] > 0.0 {
                    lit += 1;
                }
            }
            assert_eq!(
                differing, 0,
                "{}: {differing} pixels' {name} differ beyond 1e-4 relative",
                scene.name
            );
        }
        assert!(
            lit > (w * h) as usize / 4,
            "{}: only {lit} pixels lit",
            scene.name
        );
    }
}
