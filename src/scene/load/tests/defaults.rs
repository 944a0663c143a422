//! The numbers the scenes and the format promise: the paper scenes' pinned
//! parameters, and the defaults an absent field takes, which
//! `Scene::with_shapes` uses too and the book's scene format (docs/src/guide/scene-format.md) quotes.

use glam::Vec3;

use super::errors::load;
use super::{good, paper_scene, root};
use crate::scene::defaults::*;
use crate::scene::{Geometry, Light, Material, RenderParams, Scene, Shape};

#[test]
fn the_paper_scenes_match_the_pinned_numbers() {
    let g = paper_scene("glass_ball");
    assert_eq!(
        (g.camera.width, g.camera.height, g.camera.vfov_degrees),
        (512, 384, 38.0)
    );
    assert_eq!(
        (
            g.photon_map.photons_stored,
            g.photon_map.k,
            g.render.shadow_rays
        ),
        (5000, 32, 4)
    );
    assert_eq!(g.photon_map.grid_resolution, [250, 1, 250]);
    assert!(g.shapes.iter().any(|s| s.geometry
        == Geometry::Sphere {
            center: Vec3::new(0.0, 0.8, 0.0),
            radius: 0.8
        }
        && g.materials[s.material] == Material::Glass { ior: 1.5 }));
    assert!(matches!(g.lights[0], Light::Area { radiance, .. } if radiance == Vec3::splat(60.0)));

    let r = paper_scene("ring");
    assert_eq!(
        (
            r.photon_map.photons_stored,
            r.photon_map.k,
            r.render.shadow_rays
        ),
        (16000, 64, 1)
    );
    assert_eq!(
        r.lights[0],
        Light::Point {
            position: Vec3::new(0.0, 1.4, -3.2),
            intensity: Vec3::splat(40.0)
        }
    );
    assert!(r.shapes.iter().any(|s| s.geometry
        == Geometry::Cylinder {
            base: Vec3::ZERO,
            axis: Vec3::Y,
            radius: 1.0,
            height: 0.6
        }
        && r.materials[s.material]
            == Material::Mirror {
                reflectance: Vec3::new(0.95, 0.80, 0.45)
            }));

    let c = paper_scene("cornell_box");
    assert_eq!((c.camera.width, c.camera.height), (512, 512));
    assert_eq!(
        (
            c.photon_map.photons_stored,
            c.photon_map.k,
            c.render.shadow_rays
        ),
        (65000, 500, 32)
    );
    assert_eq!(c.photon_map.grid_resolution, [25, 25, 50]);
    let power = c.lights[0].power(&c.shapes);
    assert!(
        (power.x - std::f32::consts::PI * 0.25 * 25.0).abs() < 1e-4,
        "{power}"
    );
    assert_eq!(c.shapes.len(), 5 + 2 + 1, "5 walls, 2 spheres, the light");
}

#[test]
fn absent_parameters_take_the_defaults_that_with_shapes_and_the_readme_use() {
    let s = load(good()).unwrap();
    let w = Scene::with_shapes(s.shapes.clone(), s.materials.clone(), s.lights.clone());
    assert_eq!(s.render, RenderParams::default());
    assert_eq!((&s.render, &s.photon_map), (&w.render, &w.photon_map));
    assert_eq!(s.camera.up, DEFAULT_UP);
    let p = &s.photon_map;
    assert_eq!(
        (p.photons_stored, p.grid_resolution, p.k, p.max_bounces),
        (
            DEFAULT_PHOTONS_STORED,
            DEFAULT_GRID_RESOLUTION,
            DEFAULT_K,
            DEFAULT_MAX_BOUNCES
        )
    );
    // A tenth of the size of the shapes' bounds (the unit sphere: 2).
    assert_eq!(p.max_radius, DEFAULT_MAX_RADIUS_OF_SIZE * 2.0);
    assert_eq!(p.projection_resolution, DEFAULT_PROJECTION_RESOLUTION);

    // The book's scene format quotes the same numbers.
    let page = std::fs::read_to_string(root().join("docs/src/guide/scene-format.md")).unwrap();
    let format = page
        .split("```toml")
        .nth(1)
        .and_then(|s| s.split("```").next())
        .expect("the scene-format page has a TOML example");
    let line = |key: &str| {
        format
            .lines()
            .find(|l| l.trim_start().starts_with(&format!("{key} ")))
            .unwrap_or_else(|| panic!("the book's scene format has no {key}"))
    };
    let tenth = if DEFAULT_MAX_RADIUS_OF_SIZE == 0.1 {
        "default a tenth of the scene's size".to_string()
    } else {
        format!("{DEFAULT_MAX_RADIUS_OF_SIZE}")
    };
    for (key, says) in [
        ("up", if DEFAULT_UP == glam::Vec3::Y { "default y".to_string() } else { format!("{DEFAULT_UP}") }),
        ("vfov", format!("({}, {})", VFOV_RANGE.0, VFOV_RANGE.1)),
        ("width", format!("1..={MAX_IMAGE_SIDE}")),
        ("shadow_rays", format!("1..={MAX_SHADOW_RAYS}, default {DEFAULT_SHADOW_RAYS}")),
        ("max_specular_depth", format!("0..={MAX_SPECULAR_DEPTH}, default {DEFAULT_MAX_SPECULAR_DEPTH}")),
        ("photons_stored", format!("1..=2^{}, default {DEFAULT_PHOTONS_STORED}", MAX_PHOTONS_STORED.trailing_zeros())),
        ("grid_resolution", format!("1..={MAX_GRID_SIDE} each, default {DEFAULT_GRID_RESOLUTION:?}")),
        ("k", format!("1..={MAX_K}, default {DEFAULT_K}")),
        ("max_radius", tenth),
        ("max_bounces", format!("1..={MAX_BOUNCES}, default {DEFAULT_MAX_BOUNCES}")),
        ("projection_resolution", format!("{MIN_PROJECTION_RESOLUTION}..={MAX_PROJECTION_RESOLUTION}, default {DEFAULT_PROJECTION_RESOLUTION}")),
        ("glass", format!("ior in [{}, {}]", IOR_RANGE.0, IOR_RANGE.1)),
        ("metal", format!("alpha in [{}, {}]", ALPHA_RANGE.0, ALPHA_RANGE.1)),
    ] {
        assert!(line(key).contains(&says), "the book's scene format: {:?} should say {says:?}", line(key));
    }
}

/// IGI skips its VPLs where no two diffuse surfaces face each other: GLASS
/// BALL and RING (a diffuse floor under glass or metal), not the boxes; a
/// plane's two sides and a shape off it by a hair are told apart.
#[test]
fn diffuse_interreflection_is_found_where_two_diffuse_surfaces_face() {
    for (name, expected) in [
        ("cornell_box", true),
        ("cornell_box_obj", true),
        ("glass_ball", false),
        ("ring", false),
    ] {
        assert_eq!(
            paper_scene(name).has_diffuse_interreflection(),
            expected,
            "{name}"
        );
    }
    let white = Material::Diffuse {
        albedo: Vec3::splat(0.5),
    };
    let mirror = Material::Mirror {
        reflectance: Vec3::ONE,
    };
    let quad = |corner: Vec3, edge1: Vec3, edge2: Vec3, material: usize| {
        Shape::new(
            Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            },
            material,
        )
    };
    let scene = |shapes: Vec<Shape>| Scene::with_shapes(shapes, vec![white, mirror], vec![]);
    // The floor's two sides, and a mirror standing on it.
    let floor = quad(Vec3::ZERO, Vec3::X, Vec3::Z, 0);
    let under = quad(Vec3::new(2.0, 0.0, 0.0), Vec3::Z, Vec3::X, 0);
    let wall = |material| quad(Vec3::ZERO, Vec3::X, Vec3::Y, material);
    assert!(!scene(vec![floor, under, wall(1)]).has_diffuse_interreflection());
    assert!(scene(vec![floor, wall(0)]).has_diffuse_interreflection());
    // A second floor a thousandth of the scene's size higher is another
    // plane: its underside faces the first floor's light.
    let raised = quad(Vec3::new(2.0, 0.003, 0.0), Vec3::X, Vec3::Z, 0);
    assert!(scene(vec![floor, raised]).has_diffuse_interreflection());
    let ball = Shape::new(
        Geometry::Sphere {
            center: Vec3::Y,
            radius: 0.5,
        },
        0,
    );
    assert!(scene(vec![floor, ball]).has_diffuse_interreflection());
}
