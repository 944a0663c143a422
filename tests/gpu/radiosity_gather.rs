//! Final gather over the radiosity solution (`--gather-rays`): its rays are
//! final gather's (equal to the CPU twin's from the same first hits and
//! random numbers), each pixel's sum of what they bring back equals the
//! twin's sum, and around a point light, where a shadow ray is exact, every
//! ray brings back the radiosity of the elements around its hit.

use crate::common;

use photonmap::render::RadiosityOptions;
use photonmap::scene::Material;
use photonmap::twins::final_gather::gather_ray;
use photonmap::twins::radiosity::gathered_sum;

use crate::radiosity::{solve, sphere_options};

/// A point light at the centre of a closed diffuse sphere (radius 1, albedo
/// rho = 1/2, I = 1): direct irradiance 1 everywhere, so an element's
/// direct part is rho = 0.5 (exact to 1e-3 of it, the steady-state test), and
/// a gather hit's exact shadow ray gives the same. A gather hit sends back
/// (B - B_direct + rho E) / pi, so each ray's pi L is the bilinear mean of
/// the elements' B around its hit: within the range of the inside's B, to
/// 1e-3. The hits must be the twin's rays' hits, and each pixel's light the
/// twin's sum of what its rays brought.
#[test]
fn gathered_from_the_sphere_around_a_point_light_is_its_steady_state() {
    let scene = common::fixture("sphere_around_point_light");
    let rays = 8;
    let o = RadiosityOptions {
        gather_rays: rays,
        ..sphere_options()
    };
    let out = solve(&scene, o);
    let run = out.radiosity_run().unwrap();
    let gather = run.gather.as_ref().expect("gather_rays > 0 gathers");
    assert_eq!(gather.rays.batch, rays, "one batch holds every ray");
    let direct = &out.state.direct;
    let common::FirstHits {
        width: w,
        height: h,
        position: first,
        normal: first_normal,
        throughput: first_throughput,
    } = common::first_hits(direct);
    let hits = common::texels(&gather.rays.position);
    let gathered = common::texels(&gather.gathered);
    let indirect = common::texels(&run.radiosity.indirect);
    let seed = photonmap::render::RenderOptions::for_scene(&scene).seed;
    // The range of B over the inside's elements.
    let e = &run.radiosity.elements;
    let inside = e.patch_of[1] as u32;
    let b = common::texels(&run.radiosity.radiosity);
    let (b_min, b_max) = (0..e.position.len())
        .filter(|&t| e.position[t][3] > 0.0 && e.normal[t][3] as u32 == inside)
        .map(|t| b[t][0])
        .fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let (mut checked, mut apart, mut lowest, mut highest, mut sum) =
        (0u32, 0u32, f32::MAX, 0f32, 0f64);
    let mut pixels = 0;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if first[i][3] <= 0.0 {
                continue;
            }
            let mut brought = Vec::new();
            for j in 0..rays {
                let g = i + (j * w * h) as usize;
                let (p1, n1) = (common::v3(first[i]), common::v3(first_normal[i]));
                let cpu = gather_ray(&scene, p1, n1, seed, [x, y], j, 0, 0.0);
                checked += 1;
                let same = match cpu {
                    Some(hit) => {
                        hits[g][3] > 0.0 && hit.position.distance(common::v3(hits[g])) < 1e-3
                    }
                    None => hits[g][3] <= 0.0,
                };
                apart += u32::from(!same);
                let l = common::v3(gathered[g]);
                brought.push(l);
                let b = l.x * std::f32::consts::PI;
                (lowest, highest) = (lowest.min(b), highest.max(b));
                sum += f64::from(b);
            }
            let Material::Diffuse { albedo } = scene.materials[first_normal[i][3] as usize - 1]
            else {
                panic!("a first diffuse hit on a diffuse material");
            };
            let expected = gathered_sum(common::v3(first_throughput[i]), albedo, &brought, rays);
            let got = common::v3(indirect[i]);
            assert!(
                (got - expected).abs().max_element() <= 1e-5 * expected.max_element(),
                "pixel ({x}, {y}): {got} against the twin's {expected}"
            );
            pixels += 1;
        }
    }
    let mean = sum / f64::from(checked);
    eprintln!(
        "radiosity gather: {pixels} pixels, {apart} of {checked} rays apart from the twin's; pi L from {lowest:.4} to {highest:.4}, mean {mean:.4}; the inside's B from {b_min:.4} to {b_max:.4} (exact steady state 1)"
    );
    assert!(pixels > 100, "the camera sees the sphere's inside");
    assert!(apart * 200 <= checked, "{apart} of {checked} rays apart");
    assert!(
        lowest >= b_min - 1e-3 && highest <= b_max + 1e-3,
        "pi L from {lowest} to {highest} outside B's {b_min}..{b_max}"
    );
}
