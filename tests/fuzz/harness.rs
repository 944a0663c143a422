//! What the fuzz targets for `--set` overrides, camera paths and OBJ + MTL do
//! with their bytes, shared by the cargo-fuzz targets (tests/fuzz/fuzz_targets/)
//! and by the loader's unit tests (src/scene/load/tests/fuzz.rs), which replay
//! their corpora and mutate their seeds on every `cargo test`. Each loads its
//! input the way the program does and returns whether it was accepted (None:
//! not a valid input at all, such as bytes that are not UTF-8); an error is
//! fine, a panic is the bug.

#![allow(dead_code)]

use std::path::Path;

use photonmap::scene::camera_path::camera_path_from_str;
use photonmap::scene::{embedded, load_scene_str, load_scene_str_with_overrides};

/// `--set` overrides on a paper scene: the first byte picks the scene, then
/// one KEY=VALUE a line.
pub fn overrides(data: &[u8]) -> Option<bool> {
    let (&pick, rest) = data.split_first()?;
    let name = embedded::PAPER_SCENES[pick as usize % embedded::PAPER_SCENES.len()];
    let text = embedded::source(name)?;
    let sets: Vec<(String, String)> = String::from_utf8_lossy(rest)
        .lines()
        .filter_map(|l| l.split_once('='))
        .map(|(k, v)| (k.trim().to_string(), v.trim().to_string()))
        .collect();
    Some(load_scene_str_with_overrides(text, Path::new("fuzz.toml"), &sets).is_ok())
}

/// A camera path's text, against GLASS BALL's camera.
pub fn camera_path(data: &[u8]) -> Option<bool> {
    let text = std::str::from_utf8(data).ok()?;
    let scene = embedded::load("glass_ball").ok()?;
    let cameras = camera_path_from_str(
        text,
        Path::new("fuzz_path.toml"),
        &scene.camera,
        scene.origin,
    );
    if let Ok(cameras) = &cameras {
        for c in cameras {
            let (u, v, w) = c.basis();
            assert!(
                u.is_finite() && v.is_finite() && w.is_finite(),
                "a camera without a basis accepted"
            );
        }
    }
    Some(cameras.is_ok())
}

/// An OBJ and its MTL, separated by a line `%%`, loaded as a mesh of a small
/// scene (the first byte chooses whether the scene overrides the materials).
pub fn obj_mtl(data: &[u8]) -> Option<bool> {
    let (&flags, rest) = data.split_first()?;
    let text = String::from_utf8_lossy(rest);
    let (obj, mtl) = text.split_once("\n%%\n").unwrap_or((&text, ""));
    let dir = tempfile::tempdir().ok()?;
    let (obj_path, mtl_path) = (dir.path().join("mesh.obj"), dir.path().join("mesh.mtl"));
    std::fs::write(&obj_path, obj).ok()?;
    std::fs::write(&mtl_path, mtl).ok()?;
    let material = if flags & 1 == 1 {
        "material = \"white\"\n"
    } else {
        ""
    };
    let scene = format!(
        "[camera]\nposition = [0.0, 1.0, 4.0]\nlook_at = [0.0, 0.5, 0.0]\nvfov = 40.0\nwidth = 32\nheight = 24\n\
         [materials]\nwhite = {{ type = \"diffuse\", albedo = [0.7, 0.7, 0.7] }}\n\
         [[shape]]\ntype = \"mesh\"\nfile = \"mesh.obj\"\n{material}\
         [[light]]\ntype = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n"
    );
    Some(load_scene_str(&scene, &dir.path().join("scene.toml")).is_ok())
}

/// A target: its input's bytes to whether they were accepted.
pub type Target = fn(&[u8]) -> Option<bool>;

/// The targets by name, as their corpus folders are named.
pub const TARGETS: [(&str, Target); 3] = [
    ("overrides", overrides),
    ("camera_path", camera_path),
    ("obj_mtl", obj_mtl),
];
