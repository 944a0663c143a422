//! Scenes are read in f64 and rebased to a local origin before anything is
//! f32: a scene file moved far from the world's origin loads as the original
//! did, moved only in `Scene::origin`; rebasing to the camera instead puts
//! the camera at the local origin; camera paths follow their scene; the
//! limit on coordinates holds for the moved values. No GPU needed.

use std::path::Path;

use glam::{DVec3, Vec3};

use super::{dir_with, fixture};
use crate::scene::camera_path::load_camera_path;
use crate::scene::{
    embedded, load_scene_str, load_scene_str_translated, Geometry, Light, Rebase, Scene,
};
use moved_text::moved_scene_text;

/// Scene text moved by editing it, shared with the integration tests.
#[allow(dead_code)]
#[path = "../../../../tests/common/moved_text.rs"]
mod moved_text;

/// Every point of a scene, in order, as the renderer gets them (local, f32).
fn points(s: &Scene) -> Vec<Vec3> {
    let mut p = vec![s.camera.position, s.camera.look_at];
    for shape in &s.shapes {
        match shape.geometry {
            Geometry::Sphere { center, .. } => p.push(center),
            Geometry::Cylinder { base, .. } => p.push(base),
            Geometry::Parallelogram { corner, .. } => p.push(corner),
            Geometry::Triangle { v0, v1, v2 } => p.extend([v0, v1, v2]),
        }
    }
    for light in &s.lights {
        match *light {
            Light::Area { corner, .. } => p.push(corner),
            Light::Point { position, .. } => p.push(position),
            // Its triangles are shapes, counted above.
            Light::Triangles { .. } => {}
        }
    }
    if let Some((lo, hi)) = s.photon_map.grid_bounds {
        p.extend([lo, hi]);
    }
    p
}

/// The largest difference between the two scenes' points, each taken
/// relative to `shift` (a's points are compared with b's plus `shift`), in
/// f32 ulps of the scene's size; and that everything else is equal.
fn ulps_apart(a: &Scene, b: &Scene, shift: Vec3) -> f32 {
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.render, b.render);
    assert_eq!(a.photon_map.max_radius, b.photon_map.max_radius);
    assert_eq!(a.shapes.len(), b.shapes.len());
    let (pa, pb) = (points(a), points(b));
    assert_eq!(pa.len(), pb.len());
    let ulp = a.size() * f32::EPSILON;
    pa.iter()
        .zip(&pb)
        .map(|(x, y)| (*x - (*y + shift)).abs().max_element() / ulp)
        .fold(0.0, f32::max)
}

/// Moves of about 1e4, 1e6 and 1e8, each a multiple of 1024: the rounding
/// step of every embedded scene's local origin (the power of two at or
/// above its points' box; 2 for the paper scenes, 1024 for the measured
/// Cornell box in millimetres), so each moved scene is moved back exactly.
fn moves() -> [DVec3; 3] {
    [1e4, 1e6, 1e8].map(|d: f64| {
        let d = (d / 1024.0).round() * 1024.0;
        DVec3::new(d, -d, d)
    })
}

#[test]
fn every_embedded_scene_moved_far_loads_as_the_original() {
    for name in embedded::names() {
        let text = embedded::source(name).unwrap();
        let file = format!("scenes/{name}.toml");
        let original = load_scene_str(text, Path::new(&file)).unwrap();
        // The paper scenes and their variants stand around the origin, which
        // rebasing keeps.
        assert_eq!(original.origin, DVec3::ZERO, "{name}");
        for t in moves() {
            let moved =
                load_scene_str_translated(text, Path::new(&file), t, Rebase::SceneCentre).unwrap();
            // Moved back by exactly t (a multiple of the centre's rounding
            // step), so the points are the original's to within the f64
            // rounding of p + t: at most an ulp, and at 1e4 none at all.
            assert_eq!(moved.origin, t, "{name}");
            let ulps = ulps_apart(&moved, &original, Vec3::ZERO);
            eprintln!("{name} moved by {t}: {ulps} ulps");
            assert!(ulps <= 1.0, "{name} moved by {t}: {ulps} ulps");
            if t.x < 1e5 {
                assert_eq!(ulps, 0.0, "{name}");
            }
            assert_eq!(moved.offset_ratio(), original.offset_ratio(), "{name}");
        }
    }
}

#[test]
fn a_file_moved_in_its_text_loads_as_the_translated_one() {
    let text = embedded::source("glass_ball").unwrap();
    let t = DVec3::new(1e6, -1e6, 1e6);
    let (moved_text, n) = moved_scene_text(text, t);
    assert_eq!(n, 7);
    let edited = load_scene_str(&moved_text, Path::new("moved.toml")).unwrap();
    let translated =
        load_scene_str_translated(text, Path::new("moved.toml"), t, Rebase::SceneCentre).unwrap();
    assert_eq!(edited.origin, translated.origin);
    let ulps = ulps_apart(&edited, &translated, Vec3::ZERO);
    assert!(ulps <= 1.0, "{ulps} ulps");
}

#[test]
fn rebasing_to_the_camera_puts_it_at_the_local_origin() {
    let text = embedded::source("ring").unwrap();
    let original = load_scene_str(text, Path::new("ring.toml")).unwrap();
    let t = DVec3::new(1e6, -1e6, 1e6);
    let moved = load_scene_str_translated(text, Path::new("ring.toml"), t, Rebase::Camera).unwrap();
    // RING's camera, as written in its file, read in f64 and moved.
    assert_eq!(moved.origin, DVec3::new(0.0, 3.2, 3.2) + t);
    assert_eq!(moved.camera.position, Vec3::ZERO);
    // Each point is the original's less the camera, rounded once more.
    let ulps = ulps_apart(&moved, &original, -original.camera.position);
    eprintln!("camera rebase: {ulps} ulps");
    assert!(ulps <= 2.0, "{ulps} ulps");
}

#[test]
fn a_camera_path_follows_its_scene() {
    let temp = tempfile::tempdir().unwrap();
    let d = temp.path();
    let path = "frames = 3\n[[key]]\nposition = [0.0, 2.0, 5.5]\nlook_at = [0.0, 0.6, 0.0]\n[[key]]\nposition = [3.0, 1.5, 3.0]\nlook_at = [0.0, 0.4, 0.0]\n";
    let t = DVec3::new(1e6, -1e6, 1e6);
    let (moved_path, n) = moved_scene_text(path, t);
    assert_eq!(n, 4);
    std::fs::write(d.join("near.toml"), path).unwrap();
    std::fs::write(d.join("far.toml"), moved_path).unwrap();
    let text = embedded::source("glass_ball").unwrap();
    let near = load_scene_str(text, Path::new("g.toml")).unwrap();
    let far = load_scene_str_translated(text, Path::new("g.toml"), t, Rebase::SceneCentre).unwrap();
    let a = load_camera_path(&d.join("near.toml"), &near.camera, near.origin).unwrap();
    let b = load_camera_path(&d.join("far.toml"), &far.camera, far.origin).unwrap();
    assert_eq!(a.len(), 3);
    for (x, y) in a.iter().zip(&b) {
        assert_eq!((x.position, x.look_at), (y.position, y.look_at));
    }
}

#[test]
fn a_mesh_is_placed_in_f64() {
    let temp = dir_with(
        "tri.obj",
        "v 0.1 0.2 0.3\nv 1.7 0.2 0.3\nv 0.1 1.3 0.9\nf 1 2 3\n",
    );
    let d = temp.path();
    let text = fixture("placed_mesh");
    let file = d.join("mesh.toml");
    let near = load_scene_str(text, &file).unwrap();
    let t = DVec3::new(1e6, -1e6, 1e6);
    let far = load_scene_str_translated(text, &file, t, Rebase::SceneCentre).unwrap();
    assert_eq!(far.origin, t);
    // Placed in f32 at 1e6, the vertices would be off by up to 0.03.
    let ulps = ulps_apart(&far, &near, Vec3::ZERO);
    assert!(ulps <= 1.0, "{ulps} ulps");
}

#[test]
fn coordinates_past_the_limit_are_refused_where_they_are_written() {
    let text = embedded::source("ring").unwrap();
    let t = DVec3::new(2e15, 0.0, 0.0);
    let e = load_scene_str_translated(text, Path::new("ring.toml"), t, Rebase::SceneCentre)
        .unwrap_err();
    assert_eq!((e.line, e.field.as_str()), (5, "camera.position"), "{e}");
    assert!(e.message.contains("too large"), "{e}");
    // Within the limit, a point is read in f64 however large.
    let e = load_scene_str(
        &text.replace("position = [0.0, 3.2, 3.2]", "position = [1e39, 3.2, 3.2]"),
        Path::new("ring.toml"),
    )
    .unwrap_err();
    assert!(e.message.contains("too large"), "{e}");
}
