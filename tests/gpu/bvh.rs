//! The bounding volume hierarchy against a loop over every primitive, on the
//! GPU (glsl/common/scene.glsl) and in its Rust twin (src/reference/bvh.rs);
//! and watertightness: no ray and no photon leaves a closed mesh through the
//! edges its triangles share.

use crate::common;

use crate::common::Rng;

use glam::{DVec3, Vec3};
use photonmap::gpu::Gpu;
use photonmap::photon::trace::PhotonTracer;
use photonmap::scene::bvh::{self, FlatBvh};
use photonmap::scene::generate::{displaced_sphere, IndexedMesh};
use photonmap::scene::pack::SceneTextures;
use photonmap::scene::{Geometry, Light, Material, Scene, Shape};
use photonmap::twins::bvh as twin;
use photonmap::twins::intersect::{boundary_margin, intersect_geometry, ShearedRay};

/// Runs glsl/test/intersect_twin.frag in `mode` (2: closest hit, w = the
/// primitive; 3: occluded up to the direction's w) over the scene's BVH.
fn gpu_rays(
    gpu: &Gpu,
    scene: &Scene,
    tree: &FlatBvh,
    origins: &[Vec3],
    dirs: &[[f32; 4]],
    mode: i32,
) -> Vec<[f32; 4]> {
    let textures = SceneTextures::with_bvh(gpu, scene, tree).unwrap();
    let origins: Vec<[f32; 4]> = origins.iter().map(|&o| common::texel(o)).collect();
    common::intersect_twin(gpu, &textures, 256, [&origins, dirs, dirs], mode)
}

/// The closest hit by testing every primitive: (primitive, t); ties go to the first.
fn brute_force(scene: &Scene, o: Vec3, d: Vec3) -> Option<(usize, f32)> {
    let mut best: Option<(usize, f32)> = None;
    for (i, s) in scene.shapes.iter().enumerate() {
        if let Some((t, _, _)) = intersect_geometry(&s.geometry, o, d) {
            if best.is_none_or(|b| t < b.1) {
                best = Some((i, t));
            }
        }
    }
    best
}

fn diffuse_scene(shapes: Vec<Shape>) -> Scene {
    Scene::with_shapes(
        shapes,
        vec![Material::Diffuse {
            albedo: Vec3::splat(0.8),
        }],
        vec![Light::Point {
            position: Vec3::new(0.13, 0.21, -0.07),
            intensity: Vec3::ONE,
        }],
    )
}

fn v3(rng: &mut Rng, half: f64) -> Vec3 {
    (DVec3::new(rng.f64(), rng.f64(), rng.f64()) * 2.0 - 1.0).as_vec3() * half as f32
}

/// `n` random triangles in [-1, 1]^3 sized to about their spacing, with every
/// 11th degenerate (its vertices on a line) and every 13th a duplicate; plus
/// one of each analytic shape when `analytic`.
fn soup(n: usize, rng: &mut Rng, analytic: bool) -> Vec<Shape> {
    let size = 2.5 / (n as f32).cbrt();
    let mut geometry = Vec::new();
    for i in 0..n {
        let v0 = v3(rng, 1.0);
        let (v1, v2) = (v0 + v3(rng, 1.0) * size, v0 + v3(rng, 1.0) * size);
        let g = match i % 13 {
            12 if i > 0 => geometry[i - 1],
            _ if i % 11 == 10 => Geometry::Triangle {
                v0,
                v1,
                v2: v0 + 2.0 * (v1 - v0),
            },
            _ => Geometry::Triangle { v0, v1, v2 },
        };
        geometry.push(g);
    }
    if analytic {
        geometry.extend([
            Geometry::Sphere {
                center: Vec3::new(0.3, -0.2, 0.1),
                radius: 0.4,
            },
            Geometry::Cylinder {
                base: Vec3::new(-0.5, -0.6, 0.2),
                axis: Vec3::new(0.2, 1.0, 0.3).normalize(),
                radius: 0.25,
                height: 0.9,
            },
            Geometry::Parallelogram {
                corner: Vec3::new(-1.0, -0.9, -1.0),
                edge1: Vec3::new(2.0, 0.1, 0.0),
                edge2: Vec3::new(0.0, 0.05, 2.0),
            },
        ]);
    }
    geometry
        .into_iter()
        .map(|geometry| Shape::new(geometry, 0))
        .collect()
}

/// A point on the shape, or on its boundary (a vertex or an edge), to aim at.
fn aim_point(g: &Geometry, rng: &mut Rng, boundary: bool) -> Vec3 {
    match *g {
        Geometry::Triangle { v0, v1, v2 } => {
            let v = [v0, v1, v2];
            if boundary {
                let (a, b) = (v[rng.below(3)], v[rng.below(3)]);
                a + (b - a) * rng.f64() as f32
            } else {
                let (mut s, mut t) = (rng.f64() as f32, rng.f64() as f32);
                if s + t > 1.0 {
                    (s, t) = (1.0 - s, 1.0 - t);
                }
                v0 + s * (v1 - v0) + t * (v2 - v0)
            }
        }
        Geometry::Sphere { center, radius } => center + rng.unit().as_vec3() * radius,
        Geometry::Cylinder { base, axis, .. } => base + axis * rng.f64() as f32,
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => corner + edge1 * rng.f64() as f32 + edge2 * rng.f64() as f32,
    }
}

/// Rays from around the scene: a third aimed inside a random primitive, a
/// third at an edge or vertex, a third anywhere.
fn rays(scene: &Scene, rng: &mut Rng, count: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    let (lo, hi) = scene.bounds();
    let (centre, extent) = ((lo + hi) * 0.5, (hi - lo).max_element());
    for i in 0..count {
        let o = centre + v3(rng, 0.8 * extent as f64);
        let d = match i % 3 {
            2 => rng.unit().as_vec3(),
            k => {
                let g = &scene.shapes[rng.below(scene.shapes.len())].geometry;
                (aim_point(g, rng, k == 1) - o).normalize()
            }
        };
        if d.is_finite() {
            origins.push(o);
            dirs.push(d);
        }
    }
    (origins, dirs)
}

/// Whether two answers differ only where f32 rounding may decide either way:
/// the same t (a tie between primitives), or a ray that grazes a boundary.
fn explained(
    scene: &Scene,
    o: Vec3,
    d: Vec3,
    a: Option<(usize, f32)>,
    b: Option<(usize, f32)>,
) -> bool {
    let near_boundary = |p: usize| boundary_margin(&scene.shapes[p].geometry, o, d) < 1e-4;
    match (a, b) {
        (Some((pa, ta)), Some((pb, tb))) => {
            (ta - tb).abs() <= 1e-5 * ta.max(1.0) || near_boundary(pa) || near_boundary(pb)
        }
        (Some((p, _)), None) | (None, Some((p, _))) => near_boundary(p),
        (None, None) => true,
    }
}

#[test]
fn bvh_closest_hits_equal_a_loop_over_every_primitive() {
    let gpu = common::gpu();
    let mut rng = Rng(0x5eed_b4a5);
    // 1 and 10: the linear scan; 200: the threaded walk of a hierarchy in a
    // uniform block; 1000 and 100,000: the ordered walk of textures.
    let mut cases: Vec<(String, Scene)> = [1, 10, 200, 1000, 100_000]
        .into_iter()
        .map(|n| {
            let analytic = n == 1000;
            let scene = diffuse_scene(soup(n, &mut rng, analytic));
            (
                format!(
                    "{n} random triangles{}",
                    if analytic { " + analytic shapes" } else { "" }
                ),
                scene,
            )
        })
        .collect();
    for name in ["cornell_box", "glass_ball", "ring"] {
        cases.push((name.into(), common::paper_scene(name)));
    }
    for (name, scene) in &cases {
        let tree = bvh::build(scene).unwrap();
        let walk = SceneTextures::with_bvh(&gpu, scene, &tree).unwrap().walk();
        // Random triangles overlap: a box culls little, and the loop wins
        // while they are few (FlatBvh::loses_to_a_loop).
        let expected = match scene.shapes.len() {
            0..=16 => "loop",
            200 => "threaded",
            _ => "ordered",
        };
        assert!(walk.contains(expected), "{name}: {walk}");
        let (origins, dirs) = rays(scene, &mut rng, 4096);
        let dir4: Vec<[f32; 4]> = dirs.iter().map(|d| [d.x, d.y, d.z, 0.0]).collect();
        let on_gpu = gpu_rays(&gpu, scene, &tree, &origins, &dir4, 2);
        let (mut hits, mut gpu_unexplained, mut gpu_differ, mut ties) = (0, Vec::new(), 0, 0);
        for k in 0..origins.len() {
            let (o, d) = (origins[k], dirs[k]);
            let truth = brute_force(scene, o, d);
            hits += truth.is_some() as usize;
            // The twin runs the same tests in the same f32 operations: exactly the loop's t.
            let cpu = twin::closest_hit(scene, &tree, o, d).map(|(p, h)| (p, h.0));
            let threaded = twin::trace_threaded(scene, &tree, &ShearedRay::new(o, d), 1e30, false);
            assert_eq!(
                threaded.map(|(_, h)| h.0),
                truth.map(|t| t.1),
                "{name}: the threaded twin, ray {k}"
            );
            assert_eq!(
                cpu.map(|c| c.1),
                truth.map(|t| t.1),
                "{name}: twin, ray {k}"
            );
            if let Some((p, t)) = cpu {
                let own = intersect_geometry(&scene.shapes[p].geometry, o, d)
                    .unwrap()
                    .0;
                assert_eq!(own, t, "{name}: twin's primitive {p} does not give its t");
            }
            let g = on_gpu[k];
            let gpu = (g[3] >= 0.0).then_some((g[3] as usize, g[0]));
            if let Some((p, t)) = gpu {
                let own = intersect_geometry(&scene.shapes[p].geometry, o, d).map(|h| h.0);
                assert!(
                    own.is_some_and(|own| (own - t).abs() <= 1e-5 * t.max(1.0)),
                    "{name}: ray {k}: the GPU's primitive {p} gives {own:?}, not its t {t}"
                );
            }
            // GLSL may round the quadratic's terms differently: t agrees to 1e-5.
            let same_t = match (gpu, truth) {
                (Some(g), Some(t)) => (g.1 - t.1).abs() <= 1e-5 * t.1.max(1.0),
                (a, b) => a.is_none() && b.is_none(),
            };
            if gpu.map(|g| g.0) != truth.map(|t| t.0) && same_t {
                ties += 1; // duplicates and shared edges: another primitive at the same t
            } else if !same_t {
                gpu_differ += 1;
                if !explained(scene, o, d, gpu, truth) {
                    gpu_unexplained.push(format!("ray {k}: GPU {gpu:?}, loop {truth:?}"));
                }
            }
        }
        eprintln!(
            "{name}: {} primitives, {} nodes, depth {}; {hits} of {} rays hit; on the GPU {ties} ties went to another primitive, and {gpu_differ} rays differ beyond 1e-5 in t (all grazing a boundary)",
            scene.shapes.len(),
            tree.nodes.len(),
            tree.depth,
            origins.len()
        );
        assert!(
            hits > origins.len() / 4,
            "{name}: too few rays hit ({hits}) to test anything"
        );
        assert!(gpu_unexplained.is_empty(), "{name}: {gpu_unexplained:?}");
    }
}

#[test]
fn shadow_rays_stop_at_the_first_blocker_before_their_end() {
    let gpu = common::gpu();
    let mut rng = Rng(0x0cc1_0de5);
    // 300: a hierarchy in a uniform block (the threaded walk); 5000: in textures.
    for n in [300, 5000] {
        shadow_rays_stop_at_the_first_blocker(&gpu, &mut rng, n);
    }
}

fn shadow_rays_stop_at_the_first_blocker(gpu: &Gpu, rng: &mut Rng, n: usize) {
    let scene = diffuse_scene(soup(n, rng, true));
    let tree = bvh::build(&scene).unwrap();
    let (origins, dirs) = rays(&scene, rng, 4096);
    // Ends drawn around the closest hit, so both answers occur often.
    let ends: Vec<f32> = (0..origins.len())
        .map(|k| match brute_force(&scene, origins[k], dirs[k]) {
            Some((_, t)) => t * (0.5 + rng.f64() as f32),
            None => 10.0,
        })
        .collect();
    let dir4: Vec<[f32; 4]> = dirs
        .iter()
        .zip(&ends)
        .map(|(d, &e)| [d.x, d.y, d.z, e])
        .collect();
    let on_gpu = gpu_rays(gpu, &scene, &tree, &origins, &dir4, 3);
    let (mut blocked, mut bad) = (0, Vec::new());
    for k in 0..origins.len() {
        let (o, d) = (origins[k], dirs[k]);
        let truth = brute_force(&scene, o, d).is_some_and(|(_, t)| t < ends[k]);
        blocked += truth as usize;
        assert_eq!(
            twin::occluded(&scene, &tree, o, d, ends[k]),
            truth,
            "{n} triangles: twin, ray {k}"
        );
        let threaded = twin::trace_threaded(&scene, &tree, &ShearedRay::new(o, d), ends[k], true);
        assert_eq!(
            threaded.is_some(),
            truth,
            "{n} triangles: threaded twin, ray {k}"
        );
        if (on_gpu[k][0] > 0.5) != truth {
            // Only a hit within rounding of the segment's end may go either way.
            let t = brute_force(&scene, o, d).map_or(f32::MAX, |h| h.1);
            if (t - ends[k]).abs() > 1e-5 * t {
                bad.push(k);
            }
        }
    }
    assert!(
        blocked > 1000 && blocked < 3500,
        "{n} triangles: {blocked} blocked: the test needs both answers"
    );
    assert!(
        bad.is_empty(),
        "{n} triangles: GPU occlusion differs on rays {bad:?}"
    );
}

/// Rays from inside a closed mesh aimed exactly at its vertices and at points
/// on its edges: with the watertight test and conservative box test, every
/// one hits, on the GPU and in the twin.
#[test]
fn no_ray_escapes_through_the_edges_of_a_closed_mesh() {
    let gpu = common::gpu();
    let mut rng = Rng(0xc105_ed00);
    let mesh = displaced_sphere(20_000);
    let scene = diffuse_scene(mesh.shapes(0, 1.0, Vec3::ZERO));
    let tree = bvh::build(&scene).unwrap();
    let (mut origins, mut dirs) = (Vec::new(), Vec::new());
    for i in 0..16384 {
        let t = mesh.triangles[rng.below(mesh.triangles.len())];
        let (a, b) = (mesh.positions[t[0] as usize], mesh.positions[t[1] as usize]);
        let target = match i % 3 {
            0 => a,
            1 => (a + b) * 0.5,
            _ => a + (b - a) * rng.f64() as f32,
        };
        let o = v3(&mut rng, 0.5);
        origins.push(o);
        dirs.push((target - o).normalize());
    }
    let dir4: Vec<[f32; 4]> = dirs.iter().map(|d| [d.x, d.y, d.z, 0.0]).collect();
    let on_gpu = gpu_rays(&gpu, &scene, &tree, &origins, &dir4, 2);
    let gpu_escaped = on_gpu.iter().filter(|h| h[3] < 0.0).count();
    let twin_escaped = (0..origins.len())
        .filter(|&k| twin::closest_hit(&scene, &tree, origins[k], dirs[k]).is_none())
        .count();
    assert_eq!(
        (gpu_escaped, twin_escaped),
        (0, 0),
        "rays escaped (GPU, twin) of {}",
        origins.len()
    );
}

/// The surface of [-1, 1]^3 as `n` x `n` quads a face, two triangles each,
/// sharing vertices; winding outward. With `open`, one triangle is left out.
fn closed_box(n: u32, open: bool) -> IndexedMesh {
    let mut m = IndexedMesh::default();
    for axis in 0..3 {
        for side in [-1.0f32, 1.0] {
            let first = m.positions.len() as u32;
            let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
            for i in 0..=n {
                for j in 0..=n {
                    let mut p = Vec3::ZERO;
                    // The same formula on every face: a vertex on an edge of two
                    // faces is the same value in both (and +-1 is exact).
                    p[axis] = side;
                    p[u] = -1.0 + 2.0 * i as f32 / n as f32;
                    p[v] = -1.0 + 2.0 * j as f32 / n as f32;
                    m.positions.push(p);
                }
            }
            let at = |i: u32, j: u32| first + i * (n + 1) + j;
            for i in 0..n {
                for j in 0..n {
                    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
                    let (t1, t2) = if side > 0.0 {
                        ([a, b, d], [a, d, c])
                    } else {
                        ([a, d, b], [a, c, d])
                    };
                    m.triangles.push(t1);
                    m.triangles.push(t2);
                }
            }
        }
    }
    if open {
        m.triangles.remove(m.triangles.len() / 2);
    }
    m
}

/// Photons traced in a closed box lit from inside: every photon alive after
/// a bounce hits the box again, and is stored inside it. A box with one
/// triangle missing loses some, so the count can fail.
#[test]
fn a_closed_box_lit_from_inside_loses_no_photons() {
    let gpu = common::gpu();
    let count_lost = |open: bool| {
        let mut scene = diffuse_scene(closed_box(24, open).shapes(0, 1.0, Vec3::ZERO));
        scene.photon_map.max_bounces = 4;
        scene.photon_map.store_direct = true;
        scene.photon_map.caustics_only = false;
        let textures = SceneTextures::new(&gpu, &scene).unwrap();
        let tracer = PhotonTracer::new(&gpu).unwrap();
        let frames = tracer.trace(&scene, &textures, 11, 1 << 16).unwrap();
        let (position, incoming, outgoing) = (
            frames.position.read_f32(),
            frames.incoming.read_f32(),
            frames.outgoing.read_f32(),
        );
        let per_frame = (frames.width * frames.frame_height) as usize;
        let (mut alive, mut lost, mut outside) = (0, 0, 0);
        for f in 1..frames.frames as usize {
            for i in 0..per_frame {
                let (prev, this) = ((f - 1) * per_frame + i, f * per_frame + i);
                if incoming[prev * 4 + 3] == 0.0 {
                    continue;
                }
                alive += 1;
                if outgoing[this * 4 + 3] < 0.0 {
                    lost += 1;
                } else {
                    let p = Vec3::from_slice(&position[this * 4..this * 4 + 3]);
                    outside += (p.abs().max_element() > 1.0 + 1e-5) as usize;
                }
            }
        }
        (alive, lost, outside)
    };
    let (alive, lost, outside) = count_lost(false);
    eprintln!("closed box: {alive} photon paths, {lost} lost, {outside} stored outside");
    assert!(alive > 100_000, "{alive}");
    assert_eq!((lost, outside), (0, 0));
    let (_, lost_open, _) = count_lost(true);
    eprintln!(
        "box missing one of {} triangles: {lost_open} lost",
        6 * 2 * 24 * 24
    );
    assert!(lost_open > 0, "the count cannot see a hole");
}

/// Shaders compiled after packing a scene leave out the tests of primitive
/// kinds it lacks and read a small scene from a uniform block; such a
/// program refuses a scene it cannot trace, and traces one it can.
#[test]
fn a_program_specialised_to_one_scene_refuses_another() {
    use photonmap::error::Error;
    use photonmap::gpu::{DrawState, Program, Target, TexFormat, Texture};
    let gpu = common::gpu();
    let mut rng = Rng(0x5eed_5ce7);
    let triangles = diffuse_scene(soup(10, &mut rng, false));
    let spheres = diffuse_scene(vec![Shape::new(
        Geometry::Sphere {
            center: Vec3::ZERO,
            radius: 1.0,
        },
        0,
    )]);
    let packed_spheres = SceneTextures::new(&gpu, &spheres).unwrap();
    let for_spheres = Program::fullscreen(&gpu, "test/intersect_twin.frag").unwrap();
    let packed_triangles = SceneTextures::new(&gpu, &triangles).unwrap();
    let out = Texture::new(&gpu, 4, 4, TexFormat::Rgba32F).unwrap();
    let target = Target::new(&gpu, &[&out]).unwrap();
    // One closest-hit pass of `program` over `textures`.
    let draw_with = |program: &Program, textures: &SceneTextures| {
        let mut b = program.bind();
        textures.bind(&mut b);
        b.texture("u_ray_origin", &out)
            .texture("u_ray_direction", &out)
            .texture("u_ray_normal", &out)
            .int("u_primitive", 0)
            .int("u_mode", 2)
            .draw_fullscreen(&target, &DrawState::PLAIN)
    };
    let draw = |textures: &SceneTextures| draw_with(&for_spheres, textures);
    match draw(&packed_triangles) {
        Err(Error::SceneMismatch(program)) => assert!(program.contains("intersect_twin")),
        other => panic!("a sphere-only program traced triangles: {other:?}"),
    }
    draw(&packed_spheres).expect("the program's own scene");

    // A program that walks one scene's hierarchy block refuses another's,
    // whose nodes and primitives lie elsewhere in its block.
    let mesh = |n| diffuse_scene(soup(n, &mut Rng(0x5eed_b10c), false));
    let (small, larger) = (mesh(200), mesh(300));
    let packed_larger = SceneTextures::new(&gpu, &larger).unwrap();
    let packed_small = SceneTextures::new(&gpu, &small).unwrap();
    assert!(packed_small.walk().contains("threaded") && packed_larger.walk().contains("threaded"));
    let for_small = Program::fullscreen(&gpu, "test/intersect_twin.frag").unwrap();
    let draw = |textures: &SceneTextures| draw_with(&for_small, textures);
    match draw(&packed_larger) {
        Err(Error::SceneMismatch(_)) => {}
        other => panic!("a program laid out for one block traced another: {other:?}"),
    }
    draw(&packed_small).expect("the program's own scene");
}
