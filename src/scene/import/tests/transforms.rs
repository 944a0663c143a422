//! scenes/tests/import/transforms.pbrt (a stack of transforms, an instance,
//! an include, ReverseOrientation and a handedness-swapping scale on
//! one-sided emitters) loads to transforms_flat.toml, its flattened TOML;
//! without its `Scale -1 1 1` the camera is pbrt's left-handed one, and the
//! world is mirrored to keep the image.

use super::*;

fn flat() -> Scene {
    crate::scene::load_scene(&dir().join("transforms_flat.toml")).unwrap()
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
    let text = std::fs::read_to_string(dir().join("transforms.pbrt")).unwrap();
    let plain = text.replacen("  ReverseOrientation\n", "", 1);
    assert_ne!(plain, text);
    let c = convert_text("transforms.pbrt", &plain, &ImportOptions::default()).unwrap();
    let s = load_scene_str(&c.toml, Path::new("t")).unwrap();
    let n = light_normals(&s);
    assert_eq!(n[1], Some([0.0, 1.0, 0.0]), "{n:?}");
    assert_eq!(n[2], Some([0.0, -1.0, 0.0]), "{n:?}");
}

#[test]
fn a_left_handed_camera_mirrors_the_world() {
    let text = std::fs::read_to_string(dir().join("transforms.pbrt")).unwrap();
    let left = text.replacen("Scale -1 1 1\n", "", 1);
    assert_ne!(left, text);
    let c = convert_text("transforms.pbrt", &left, &ImportOptions::default()).unwrap();
    assert!(c.toml.contains("mirrored"), "{}", c.toml);
    let s = load_scene_str(&c.toml, Path::new("t")).unwrap();
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
    let text = std::fs::read_to_string(dir().join("transforms.pbrt")).unwrap();
    let tall = text.replace(
        "xresolution\" [ 64 ] \"integer yresolution\" [ 48 ]",
        "xresolution\" [ 48 ] \"integer yresolution\" [ 96 ]",
    );
    assert_ne!(tall, text);
    let c = convert_text("transforms.pbrt", &tall, &ImportOptions::default()).unwrap();
    let s = load_scene_str(&c.toml, Path::new("t")).unwrap();
    let expected = 2.0 * ((15f64.to_radians()).tan() * 2.0).atan().to_degrees();
    assert!(
        (f64::from(s.camera.vfov_degrees) - expected).abs() < 1e-4,
        "{}",
        s.camera.vfov_degrees
    );
}

#[test]
fn the_mitsuba_scene_loads_as_the_same_flattened_toml() {
    assert_same(&load("transforms.xml"), &flat());
}

#[test]
fn mitsuba_fov_axis_x_is_converted_to_the_vertical_fov() {
    let text = std::fs::read_to_string(dir().join("transforms.xml")).unwrap();
    let x = text.replace("value=\"y\"", "value=\"x\"");
    let c = convert_text("transforms.xml", &x, &ImportOptions::default()).unwrap();
    let s = load_scene_str(&c.toml, Path::new("t")).unwrap();
    let expected = 2.0
        * ((15f64.to_radians()).tan() * 48.0 / 64.0)
            .atan()
            .to_degrees();
    assert!(
        (f64::from(s.camera.vfov_degrees) - expected).abs() < 1e-4,
        "{}",
        s.camera.vfov_degrees
    );
}
