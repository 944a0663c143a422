//! Mutation fuzzing of scene and OBJ loading (cargo-fuzz needs a nightly
//! compiler this project's toolchain does not have): mutated inputs from
//! tests/fuzz_corpus/ must never panic, and whatever loads must be finite.
//! PHOTONMAP_FUZZ_ITERATIONS sets the length of a run (default 3000 a target),
//! PHOTONMAP_FUZZ_SEED the mutations.
//! Inputs that once broke the loader live in tests/fuzz_corpus/regressions/.
//! The newer inputs (`--set` overrides, camera paths, OBJ with MTL) go
//! through tests/fuzz/harness.rs, as their cargo-fuzz targets do.

mod common;
#[path = "fuzz/harness.rs"]
mod harness;

use common::Rng;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use photonmap::scene::{load_scene, load_scene_str, Geometry, Light, Scene};

/// A scene whose one shape is the mesh `fuzz.obj` beside it.
const MESH_SCENE: &str = "[camera]\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nvfov = 40.0\nwidth = 8\nheight = 8\n[materials]\nm = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }\n[[shape]]\ntype = \"mesh\"\nfile = \"fuzz.obj\"\nmaterial = \"m\"\n[[light]]\ntype = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n";

const SPECIAL: [&str; 14] = [
    "nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "1e39",
    "-1e39",
    "1e-45",
    "99999999999999999999",
    "-0.0",
    "\"x\"",
    "[]",
    "{}",
    "true",
];

fn mutate(input: &str, rng: &mut Rng) -> String {
    let mut s = input.to_string();
    for _ in 0..1 + rng.below(4) {
        let lines: Vec<String> = s.lines().map(str::to_string).collect();
        s = match rng.below(7) {
            // Replace a number with a special value.
            0 => {
                let numbers: Vec<(usize, usize)> = find_numbers(&s);
                if numbers.is_empty() {
                    s
                } else {
                    let (a, b) = numbers[rng.below(numbers.len())];
                    format!(
                        "{}{}{}",
                        &s[..a],
                        SPECIAL[rng.below(SPECIAL.len())],
                        &s[b..]
                    )
                }
            }
            1 if !lines.is_empty() => {
                let mut l = lines.clone();
                l.remove(rng.below(l.len()));
                l.join("\n")
            }
            2 if !lines.is_empty() => {
                let mut l = lines.clone();
                let i = rng.below(l.len());
                l.insert(i, l[i].clone());
                l.join("\n")
            }
            3 => {
                let mut b = s.into_bytes();
                if !b.is_empty() {
                    let i = rng.below(b.len());
                    let alphabet = b" =[]{},.\"#\n0123456789abcdefnx-";
                    b[i] = alphabet[rng.below(alphabet.len())];
                }
                String::from_utf8_lossy(&b).into_owned()
            }
            4 => {
                let cut = rng.below(s.len() + 1);
                let cut = (0..=cut)
                    .rev()
                    .find(|&c| s.is_char_boundary(c))
                    .unwrap_or(0);
                s[..cut].to_string()
            }
            5 if lines.len() > 1 => {
                let mut l = lines.clone();
                let (a, b) = (rng.below(l.len()), rng.below(l.len()));
                l.swap(a, b);
                l.join("\n")
            }
            _ => {
                let i = (0..=rng.below(s.len() + 1).min(s.len()))
                    .rev()
                    .find(|&c| s.is_char_boundary(c))
                    .unwrap_or(0);
                format!(
                    "{}{}{}",
                    &s[..i],
                    SPECIAL[rng.below(SPECIAL.len())],
                    &s[i..]
                )
            }
        };
    }
    s
}

fn find_numbers(s: &str) -> Vec<(usize, usize)> {
    let b = s.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        if b[i].is_ascii_digit() || (b[i] == b'-' && i + 1 < b.len() && b[i + 1].is_ascii_digit()) {
            let start = i;
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_digit() || b[i] == b'.' || b[i] == b'e' || b[i] == b'-')
            {
                i += 1;
            }
            out.push((start, i));
        } else {
            i += 1;
        }
    }
    out
}

/// Everything a loaded scene holds is finite and in range.
fn assert_sane(scene: &Scene, input: &str) {
    let v = |p: glam::Vec3| assert!(p.is_finite(), "non-finite value accepted from:\n{input}");
    v(scene.camera.position);
    v(scene.camera.look_at);
    assert!(
        (1..=16384).contains(&scene.camera.width) && (1..=16384).contains(&scene.camera.height)
    );
    for s in &scene.shapes {
        match s.geometry {
            Geometry::Sphere { center, radius } => {
                v(center);
                assert!(radius.is_finite() && radius > 0.0);
            }
            Geometry::Cylinder {
                base,
                axis,
                radius,
                height,
            } => {
                v(base);
                v(axis);
                assert!(radius > 0.0 && height > 0.0 && radius.is_finite() && height.is_finite());
            }
            Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            } => [corner, edge1, edge2].into_iter().for_each(v),
            Geometry::Triangle { v0, v1, v2 } => [v0, v1, v2].into_iter().for_each(v),
        }
        assert!(s.material < scene.materials.len());
    }
    for l in &scene.lights {
        match *l {
            Light::Area {
                corner,
                edge1,
                edge2,
                normal,
                radiance,
            } => [corner, edge1, edge2, normal, radiance]
                .into_iter()
                .for_each(v),
            Light::Point {
                position,
                intensity,
            } => [position, intensity].into_iter().for_each(v),
            Light::Triangles {
                first,
                count,
                radiance,
            } => {
                v(radiance);
                assert!(first + count <= scene.shapes.len() && count > 0);
            }
        }
    }
    assert!(scene.photon_map.max_radius.is_finite() && scene.photon_map.max_radius > 0.0);
}

fn corpus() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("fuzz_corpus")
}

/// PHOTONMAP_FUZZ_SEED varies the mutations between long runs.
fn seed(base: u64) -> u64 {
    base ^ std::env::var("PHOTONMAP_FUZZ_SEED")
        .ok()
        .and_then(|v| v.parse::<u64>().ok())
        .unwrap_or(0)
        .wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

fn iterations() -> usize {
    std::env::var("PHOTONMAP_FUZZ_ITERATIONS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(3000)
}

fn files(ext: &str) -> Vec<String> {
    let mut out = Vec::new();
    for dir in [corpus(), corpus().join("regressions")] {
        if let Ok(rd) = std::fs::read_dir(&dir) {
            for e in rd.flatten() {
                if e.path().extension().and_then(|x| x.to_str()) == Some(ext) {
                    out.push(std::fs::read_to_string(e.path()).unwrap());
                }
            }
        }
    }
    out.sort();
    out
}

#[test]
fn mutated_scenes_never_panic_and_accepted_ones_are_finite() {
    let seeds = files("toml");
    assert!(seeds.len() >= 3);
    let mut rng = Rng(seed(0x5eed_f00d));
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..iterations() {
        let input = mutate(&seeds[rng.below(seeds.len())], &mut rng);
        let result = catch_unwind(AssertUnwindSafe(|| {
            load_scene_str(&input, Path::new("fuzz.toml"))
        }));
        match result {
            Err(_) => panic!("the loader panicked on:\n{input}"),
            Ok(Ok(scene)) => {
                assert_sane(&scene, &input);
                accepted += 1;
            }
            Ok(Err(e)) => {
                assert!(
                    e.line > 0 || e.field != "(file)",
                    "an error without a place: {e}"
                );
                refused += 1;
            }
        }
    }
    eprintln!("{accepted} mutated scenes accepted, {refused} refused");
    assert!(
        accepted > 0 && refused > 0,
        "the mutations must reach both outcomes"
    );
}

#[test]
fn mutated_obj_files_never_panic_and_accepted_ones_are_finite() {
    let seeds = files("obj");
    assert!(seeds.len() >= 2);
    let dir = std::env::temp_dir().join(format!("photonmap-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), MESH_SCENE).unwrap();
    let mut rng = Rng(seed(0x0b1_f00d));
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..iterations() {
        let input = mutate(&seeds[rng.below(seeds.len())], &mut rng);
        std::fs::write(dir.join("fuzz.obj"), &input).unwrap();
        match catch_unwind(AssertUnwindSafe(|| load_scene(&dir.join("scene.toml")))) {
            Err(_) => panic!("OBJ loading panicked on:\n{input}"),
            Ok(Ok(scene)) => {
                assert_sane(&scene, &input);
                accepted += 1;
            }
            Ok(Err(e)) => {
                assert!(
                    e.message.contains("OBJ") || e.message.contains("primitives"),
                    "{e}"
                );
                refused += 1;
            }
        }
    }
    eprintln!("{accepted} mutated OBJ files accepted, {refused} refused");
    assert!(accepted > 0 && refused > 0);
}

/// The cargo-fuzz corpus (tests/fuzz/corpus/, kept minimised) replayed
/// through the loaders on every test run, without libFuzzer.
#[test]
fn the_cargo_fuzz_corpus_loads_without_panics() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus");
    let mut replayed = 0;
    for entry in std::fs::read_dir(root.join("scene_toml"))
        .unwrap()
        .flatten()
    {
        let bytes = std::fs::read(entry.path()).unwrap();
        if let Ok(text) = std::str::from_utf8(&bytes) {
            match catch_unwind(AssertUnwindSafe(|| {
                load_scene_str(text, Path::new("corpus.toml"))
            })) {
                Err(_) => panic!("the loader panicked on {}", entry.path().display()),
                Ok(Ok(scene)) => assert_sane(&scene, text),
                Ok(Err(_)) => {}
            }
        }
        replayed += 1;
    }
    let dir = std::env::temp_dir().join(format!("photonmap-corpus-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("scene.toml"), MESH_SCENE).unwrap();
    for entry in std::fs::read_dir(root.join("obj_mesh")).unwrap().flatten() {
        std::fs::copy(entry.path(), dir.join("fuzz.obj")).unwrap();
        match catch_unwind(AssertUnwindSafe(|| load_scene(&dir.join("scene.toml")))) {
            Err(_) => panic!("OBJ loading panicked on {}", entry.path().display()),
            Ok(Ok(scene)) => assert_sane(&scene, &entry.path().display().to_string()),
            Ok(Err(_)) => {}
        }
        replayed += 1;
    }
    assert!(replayed > 1000, "{replayed} corpus files");
}

/// Mutates the seeds of one harness target (files of `ext` in tests/fuzz_corpus/,
/// each prefixed with a random byte when `prefix`), and requires no panic and
/// both outcomes.
fn mutate_target(
    what: &str,
    ext: &str,
    prefix: bool,
    target: fn(&[u8]) -> Option<bool>,
    rng_seed: u64,
) {
    let seeds = files(ext);
    assert!(!seeds.is_empty(), "no .{ext} seeds");
    let mut rng = Rng(seed(rng_seed));
    let (mut accepted, mut refused) = (0, 0);
    for _ in 0..iterations() / 3 {
        let text = mutate(&seeds[rng.below(seeds.len())], &mut rng);
        let mut input = Vec::new();
        if prefix {
            input.push(rng.below(256) as u8);
        }
        input.extend_from_slice(text.as_bytes());
        match catch_unwind(AssertUnwindSafe(|| target(&input))) {
            Err(_) => panic!("{what} panicked on:\n{}", String::from_utf8_lossy(&input)),
            Ok(Some(true)) => accepted += 1,
            Ok(_) => refused += 1,
        }
    }
    eprintln!("{accepted} mutated {what} accepted, {refused} refused");
    assert!(
        accepted > 0 && refused > 0,
        "the mutations must reach both outcomes"
    );
}

#[test]
fn mutated_overrides_never_panic() {
    mutate_target("--set overrides", "set", true, harness::overrides, 0x5e7);
}

#[test]
fn mutated_camera_paths_never_panic_and_accepted_cameras_have_a_basis() {
    mutate_target("camera paths", "path", false, harness::camera_path, 0xca3);
}

#[test]
fn mutated_obj_and_mtl_files_never_panic() {
    mutate_target("OBJ + MTL pairs", "objmtl", true, harness::obj_mtl, 0x3711);
}

/// The corpora of the harness targets, replayed.
#[test]
fn the_cargo_fuzz_corpora_of_the_newer_inputs_load_without_panics() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus");
    for (name, target) in harness::TARGETS {
        let mut replayed = 0;
        for entry in std::fs::read_dir(root.join(name)).unwrap().flatten() {
            let bytes = std::fs::read(entry.path()).unwrap();
            if catch_unwind(AssertUnwindSafe(|| target(&bytes))).is_err() {
                panic!("{name} panicked on {}", entry.path().display());
            }
            replayed += 1;
        }
        assert!(replayed > 0, "no corpus for {name}");
    }
}
