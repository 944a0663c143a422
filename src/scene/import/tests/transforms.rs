//! scenes/tests/import/transforms.pbrt (a stack of transforms, an instance,
//! an include, ReverseOrientation and a handedness-swapping scale on
//! one-sided emitters) loads to transforms_flat.toml, its flattened TOML;
//! without its `Scale -1 1 1` the camera is pbrt's left-handed one, and the
//! world is mirrored to keep the image.

use super::*;

fn flat() -> Scene {
    crate::scene::load_scene(&dir().join("transforms_flat.toml")).unwrap()
}

/// The fixture `name` with `edit`, which must change it, converted and
/// loaded; with the TOML it converted to.
fn load_edited(name: &str, edit: impl FnOnce(&str) -> String) -> (String, Scene) {
    let text = fixture_text(name);
    let edited = edit(&text);
    assert_ne!(edited, text);
    convert_and_load(name, &edited)
}

/// The scene's vertical field of view is `expected` degrees.
fn assert_vfov(s: &Scene, expected: f64) {
    assert!(
        (f64::from(s.camera.vfov_degrees) - expected).abs() < 1e-4,
        "{}",
        s.camera.vfov_degrees
    );
}

/// The shapes (lights' included) and lights of two scenes agree, in order.
fn assert_same(a: &Scene, b: &Scene) {
    assert_eq!(a.shapes.len(), b.shapes.len());
    for (x, y) in a.shapes.iter().zip(&b.shapes) {
        let (kx, ky) = (key(a, &x.geometry), key(b, &y.geometry));
        let same = kx.0.len() == ky.0.len()
            && kx.0.iter().zip(&ky.0).all(|(p, q)| close(*p, *q, 1e-5))
            && kx.1.iter().zip(&ky.1).all(|(p, q)| (p - q).abs() < 1e-6);
        assert!(same, "{x:?}\n{y:?}");
        assert_eq!(a.materials[x.material], b.materials[y.material]);
    }
    assert_eq!(light_power(a), light_power(b));
    assert_eq!(light_normals(a), light_normals(b));
    let (ca, cb) = (&a.camera, &b.camera);
    let dir = |c: &crate::scene::Camera| (c.look_at - c.position).normalize();
    assert!(close(world(a, ca.position), world(b, cb.position), 1e-5));
    assert!((dir(ca) - dir(cb)).length() < 1e-6, "{ca:?} {cb:?}");
    let up = |c: &crate::scene::Camera| c.up.reject_from(dir(c)).normalize();
    assert!((up(ca) - up(cb)).length() < 1e-6, "{ca:?} {cb:?}");
    assert_eq!(
        (ca.vfov_degrees, ca.width, ca.height),
        (cb.vfov_degrees, cb.width, cb.height)
    );
}

#[test]
fn a_stack_of_transforms_loads_as_its_flattened_toml() {
    assert_same(&load("transforms.pbrt"), &flat());
}

#[test]
fn without_reverse_orientation_the_quad_light_faces_up() {
    let (_, s) = load_edited("transforms.pbrt", |t| {
        t.replacen("  ReverseOrientation\n", "", 1)
    });
    let n = light_normals(&s);
    assert_eq!(n[1], Some([0.0, 1.0, 0.0]), "{n:?}");
    assert_eq!(n[2], Some([0.0, -1.0, 0.0]), "{n:?}");
}

#[test]
fn a_left_handed_camera_mirrors_the_world() {
    let (toml, s) = load_edited("transforms.pbrt", |t| t.replacen("Scale -1 1 1\n", "", 1));
    assert!(toml.contains("mirrored"), "{toml}");
    // The camera stands at x = 0 looking along -z: the mirror is x -> -x.
    let sphere = s
        .shapes
        .iter()
        .find_map(|x| match x.geometry {
            Geometry::Sphere { center, .. } => Some(world(&s, center)),
            _ => None,
        })
        .unwrap();
    assert!(close(sphere, [-1.5, 0.5, 0.0], 1e-6), "{sphere:?}");
}

#[test]
fn pbrt_fov_spans_the_shorter_side() {
    let (_, s) = load_edited("transforms.pbrt", |t| {
        t.replace(
            "xresolution\" [ 64 ] \"integer yresolution\" [ 48 ]",
            "xresolution\" [ 48 ] \"integer yresolution\" [ 96 ]",
        )
    });
    let expected = 2.0 * ((15f64.to_radians()).tan() * 2.0).atan().to_degrees();
    assert_vfov(&s, expected);
}

#[test]
fn the_mitsuba_scene_loads_as_the_same_flattened_toml() {
    assert_same(&load("transforms.xml"), &flat());
}

#[test]
fn mitsuba_fov_axis_x_is_converted_to_the_vertical_fov() {
    let x = fixture_text("transforms.xml").replace("value=\"y\"", "value=\"x\"");
    let (_, s) = convert_and_load("transforms.xml", &x);
    let expected = 2.0
        * ((15f64.to_radians()).tan() * 48.0 / 64.0)
            .atan()
            .to_degrees();
    assert_vfov(&s, expected);
}
