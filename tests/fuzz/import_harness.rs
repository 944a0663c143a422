//! What the fuzz targets for the importers do with their bytes: a pbrt-v4
//! scene, a Mitsuba 3 XML scene and a PLY mesh. Shared by the cargo-fuzz
//! targets `pbrt_scene`, `mitsuba_scene` and `ply_mesh`
//! (tests/fuzz/fuzz_targets/) and by the importers' unit tests
//! (src/scene/import/tests/fuzz.rs), which replay their corpora
//! (tests/fuzz/corpus/<target>/) on every `cargo test`. Each returns whether
//! the input was accepted; an error is fine, a panic is the bug.

#![allow(dead_code)]

use std::path::Path;

use photonmap::scene::import::ply::parse_ply;
use photonmap::scene::import::{convert_bytes, Format, ImportOptions, NoFiles};
use photonmap::scene::load_scene_str;

/// A scene file's bytes converted (strictly, then under `--lenient`, with
/// `-D spp=4`; includes and meshes are missing) and, where that succeeds,
/// the TOML loaded. Accepted: the strict conversion loaded.
fn scene(format: Format, data: &[u8], name: &str) -> Option<bool> {
    let path = Path::new(name);
    let mut accepted = false;
    for lenient in [false, true] {
        let opts = ImportOptions {
            lenient,
            defines: vec![("spp".into(), "4".into())],
        };
        if let Ok(c) = convert_bytes(format, data, path, &NoFiles, &opts) {
            let loaded = load_scene_str(&c.toml, path);
            if let Ok(s) = &loaded {
                assert!(
                    s.camera.position.is_finite() && s.size().is_finite(),
                    "a non-finite scene accepted"
                );
            }
            accepted |= !lenient && loaded.is_ok();
        }
    }
    Some(accepted)
}

/// A pbrt-v4 scene file.
pub fn pbrt_scene(data: &[u8]) -> Option<bool> {
    scene(Format::Pbrt, data, "fuzz.pbrt")
}

/// A Mitsuba 3 XML scene file.
pub fn mitsuba_scene(data: &[u8]) -> Option<bool> {
    scene(Format::Mitsuba, data, "fuzz.xml")
}

/// A PLY mesh; what it accepts is finite and its faces index its vertices.
pub fn ply_mesh(data: &[u8]) -> Option<bool> {
    let Ok(mesh) = parse_ply(data) else {
        return Some(false);
    };
    assert!(mesh.positions.iter().all(|p| p.is_finite()));
    let n = mesh.positions.len();
    assert!(
        mesh.triangles.iter().flatten().all(|&i| i < n),
        "a face index out of range accepted"
    );
    if let Some(normals) = &mesh.normals {
        assert_eq!(normals.len(), n);
    }
    Some(true)
}

/// A target: its input's bytes to whether they were accepted.
pub type Target = fn(&[u8]) -> Option<bool>;

/// The targets by name, as their corpus folders are named.
pub const TARGETS: [(&str, Target); 3] = [
    ("pbrt_scene", pbrt_scene),
    ("mitsuba_scene", mitsuba_scene),
    ("ply_mesh", ply_mesh),
];
