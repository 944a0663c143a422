//! glsl/common/bsdf.glsl against its twin (src/twins/bsdf.rs) on random
//! queries: evaluate, pdf and sample of the diffuse lobe and of smooth-ish to
//! rough, isotropic and anisotropic conductors (Trowbridge-Reitz and
//! Beckmann, height-correlated and separable masking), about a tilted normal.

use crate::common;
use crate::common::Rng;

use glam::{Vec2, Vec3};
use photonmap::gpu::{DrawState, Program, Target, TexFormat, Texture};
use photonmap::layout::{MICROFACET_BECKMANN, MICROFACET_SEPARABLE};
use photonmap::twins::bsdf::{eval, pdf, sample, Bsdf, Frame};

const WIDTH: u32 = 64;
const QUERIES: usize = 64 * 32;

fn close(a: f32, b: f32, scale: f32) -> bool {
    (a - b).abs() <= 1e-4 * scale.max(1e-3)
}

#[test]
fn the_bsdf_layer_matches_its_twin() {
    let gpu = common::gpu();
    let program = Program::fullscreen(&gpu, "test/bsdf_twin.frag").unwrap();
    let normal = Vec3::new(0.3, -0.5, 0.8).normalize();
    let frame = Frame::around(normal);
    let gold = (
        Vec3::new(0.143, 0.374, 1.442),
        Vec3::new(3.983, 2.385, 1.603),
    );
    let bsdfs = [
        Bsdf::diffuse(Vec3::new(0.7, 0.4, 0.1)),
        Bsdf::conductor(Vec3::ONE, gold.0, gold.1, Vec2::splat(0.1)),
        Bsdf::conductor(
            Vec3::new(0.9, 0.8, 1.0),
            gold.0,
            gold.1,
            Vec2::new(0.05, 0.6),
        ),
        Bsdf::conductor(
            Vec3::ONE,
            Vec3::splat(1.2),
            Vec3::splat(3.0),
            Vec2::splat(1.0),
        ),
        Bsdf::conductor(Vec3::ONE, gold.0, gold.1, Vec2::splat(0.3))
            .with_model(MICROFACET_BECKMANN | MICROFACET_SEPARABLE),
        Bsdf::conductor(Vec3::ONE, gold.0, gold.1, Vec2::new(0.1, 0.4))
            .with_model(MICROFACET_BECKMANN),
        Bsdf::conductor(Vec3::ONE, gold.0, gold.1, Vec2::splat(0.3))
            .with_model(MICROFACET_SEPARABLE),
    ];
    let mut rng = Rng(0xb5df);
    let direction = |rng: &mut Rng| -> Vec3 {
        // Mostly above the surface, some below, some grazing.
        let v = rng.unit().as_vec3();
        if rng.f64() < 0.85 {
            (v + normal * (v.dot(normal).abs() + 1e-3 * rng.f64() as f32) * 2.0).normalize()
        } else {
            v
        }
    };
    let height = (QUERIES as u32).div_ceil(WIDTH);
    for b in bsdfs {
        let (mut wo, mut wi, mut u) = (vec![], vec![], vec![]);
        for _ in 0..QUERIES {
            wo.push(direction(&mut rng));
            wi.push(direction(&mut rng));
            u.push(Vec2::new(rng.f64() as f32, rng.f64() as f32));
        }
        let upload = |texels: Vec<[f32; 4]>| {
            let d: Vec<f32> = texels.into_iter().flatten().collect();
            Texture::from_texels(&gpu, WIDTH, height, TexFormat::Rgba32F, &d).unwrap()
        };
        let two = u.iter().map(|u| [u.x, u.y, 0.0, 0.0]).collect();
        let (two, to, ti) = (
            upload(two),
            upload(wo.iter().map(|&v| common::texel(v)).collect()),
            upload(wi.iter().map(|&v| common::texel(v)).collect()),
        );
        let outs: Vec<Texture> = (0..3)
            .map(|_| Texture::new(&gpu, WIDTH, height, TexFormat::Rgba32F).unwrap())
            .collect();
        let target = Target::new(&gpu, &outs.iter().collect::<Vec<_>>()).unwrap();
        program
            .bind()
            .texture("u_wo", &to)
            .texture("u_wi", &ti)
            .texture("u_u", &two)
            .int("u_kind", b.kind as i32)
            .vec3("u_color", b.color.into())
            .vec2("u_alpha", b.alpha.into())
            .vec3("u_eta", b.eta.into())
            .vec3("u_k", b.k.into())
            .vec3("u_normal", normal.into())
            .int("u_model", b.model as i32)
            .draw_fullscreen(&target, &DrawState::PLAIN)
            .unwrap();
        let [evals, samples, weights] = [0, 1, 2].map(|i| common::texels(&outs[i]));
        let mut sampled = 0;
        for i in 0..QUERIES {
            let (f, p) = (
                eval(&b, &frame, wo[i], wi[i]),
                pdf(&b, &frame, wo[i], wi[i]),
            );
            let g = evals[i];
            let scale = f.max_element();
            assert!(
                (0..3).all(|c| close(g[c], f[c], scale)) && close(g[3], p, p),
                "{b:?}: f, pdf ({wo:?}, {wi:?}) = {f}, {p} on the CPU, {g:?} on the GPU",
                wo = wo[i],
                wi = wi[i]
            );
            let s = sample(&b, &frame, wo[i], u[i]);
            let (gs, gw) = (samples[i], weights[i]);
            assert_eq!(
                gs[3] as u32, s.lobe,
                "{b:?}: lobe at wo {} u {}",
                wo[i], u[i]
            );
            if s.lobe == 0 {
                continue;
            }
            sampled += 1;
            let w_scale = s.weight.max_element();
            // A weight (at most about 1) to 1e-4 absolute: at a grazing
            // sample the cosine of wi is a difference of nearly equal terms,
            // whose rounding GLSL's looser division and square root change.
            assert!(
                (common::v3(gs) - s.wi).length() < 1e-4
                    && (0..3).all(|c| (gw[c] - s.weight[c]).abs() <= 1e-4 * w_scale.max(1.0))
                    && close(gw[3], s.pdf, s.pdf),
                "{b:?}: sample at wo {} u {}: {s:?} on the CPU, {gs:?} {gw:?} on the GPU",
                wo[i],
                u[i]
            );
        }
        assert!(sampled > QUERIES / 2, "{b:?}: only {sampled} samples");
    }
}
