//! Mutation fuzzing of scene and OBJ loading (cargo-fuzz needs a nightly
//! compiler this project's toolchain does not have): mutated inputs from
//! tests/fuzz_corpus/ must never panic, and whatever loads must be finite.
//! PHOTONMAP_FUZZ_ITERATIONS sets the length of a run (default 3000 a target),
//! PHOTONMAP_FUZZ_SEED the mutations.
//! Inputs that once broke the loader live in tests/fuzz_corpus/regressions/.
//! The newer inputs (`--set` overrides, camera paths, OBJ with MTL) go
//! through tests/fuzz/harness.rs, as their cargo-fuzz targets do.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use super::{fixture, root};
use crate::scene::{load_scene, load_scene_str, Geometry, Light, Scene, SceneError};
use rng::Rng;

/// What the cargo-fuzz targets do with their bytes (the crate's library is
/// `photonmap` there, and here through `extern crate self`).
#[path = "../../../../tests/fuzz/harness.rs"]
mod harness;

/// The integration tests' random source.
#[allow(dead_code)]
#[path = "../../../../tests/common/rng.rs"]
mod rng;

/// A scene whose one shape is the mesh `fuzz.obj` beside it.
fn mesh_scene() -> &'static str {
    fixture("fuzz_mesh")
}

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
    root().join("tests").join("fuzz_corpus")
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

/// Loads `n` mutations of `seeds` (each prefixed with a random byte when
/// `prefix`) through `load`; a panic fails the test, naming `what` and the
/// input. `accepted` judges each outcome, with the mutated text, outside the
/// unwinding guard (so that its own assertions fail as themselves).
/// Returns how many were accepted and refused.
fn run_mutations<T>(
    what: &str,
    seeds: &[String],
    rng: &mut Rng,
    n: usize,
    prefix: bool,
    load: impl Fn(&[u8]) -> T,
    mut accepted: impl FnMut(T, &str) -> bool,
) -> (usize, usize) {
    let (mut yes, mut no) = (0, 0);
    for _ in 0..n {
        let text = mutate(&seeds[rng.below(seeds.len())], rng);
        let mut input = Vec::new();
        if prefix {
            input.push(rng.below(256) as u8);
        }
        input.extend_from_slice(text.as_bytes());
        let outcome = catch_unwind(AssertUnwindSafe(|| load(&input)))
            .unwrap_or_else(|_| panic!("{what} panicked on:\n{}", String::from_utf8_lossy(&input)));
        if accepted(outcome, &text) {
            yes += 1;
        } else {
            no += 1;
        }
    }
    (yes, no)
}

/// Says how many mutated `what` were accepted and refused, and requires
/// some of each.
fn both_outcomes(what: &str, accepted: usize, refused: usize) {
    eprintln!("{accepted} mutated {what} accepted, {refused} refused");
    assert!(
        accepted > 0 && refused > 0,
        "the mutations must reach both outcomes"
    );
}

/// Judges a loader's outcome: a scene it accepts must be sane (`assert_sane`),
/// and `check_refusal` checks each error. True when accepted.
fn sane_if_accepted(
    check_refusal: impl Fn(&SceneError),
) -> impl Fn(Result<Scene, SceneError>, &str) -> bool {
    move |result, input| match result {
        Ok(scene) => {
            assert_sane(&scene, input);
            true
        }
        Err(e) => {
            check_refusal(&e);
            false
        }
    }
}

/// A mutated scene's text (mutations of text stay text).
fn utf8(input: &[u8]) -> &str {
    std::str::from_utf8(input).unwrap()
}

#[test]
fn mutated_scenes_never_panic_and_accepted_ones_are_finite() {
    let seeds = files("toml");
    assert!(seeds.len() >= 3);
    let mut rng = Rng(seed(0x5eed_f00d));
    let load = |input: &[u8]| load_scene_str(utf8(input), Path::new("fuzz.toml"));
    let judge = sane_if_accepted(|e| {
        assert!(
            e.line > 0 || e.field != "(file)",
            "an error without a place: {e}"
        );
    });
    let n = iterations();
    let (accepted, refused) = run_mutations("the loader", &seeds, &mut rng, n, false, load, judge);
    both_outcomes("scenes", accepted, refused);
}

#[test]
fn mutated_obj_files_never_panic_and_accepted_ones_are_finite() {
    let seeds = files("obj");
    assert!(seeds.len() >= 2);
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    std::fs::write(dir.join("scene.toml"), mesh_scene()).unwrap();
    let mut rng = Rng(seed(0x0b1_f00d));
    let load = |input: &[u8]| {
        std::fs::write(dir.join("fuzz.obj"), input).unwrap();
        load_scene(&dir.join("scene.toml"))
    };
    let judge = sane_if_accepted(|e| {
        assert!(
            e.message.contains("OBJ") || e.message.contains("primitives"),
            "{e}"
        );
    });
    let n = iterations();
    let (accepted, refused) = run_mutations("OBJ loading", &seeds, &mut rng, n, false, load, judge);
    eprintln!("{accepted} mutated OBJ files accepted, {refused} refused");
    assert!(accepted > 0 && refused > 0);
}

/// The files of one target's cargo-fuzz corpus (tests/fuzz/corpus/<target>/).
fn corpus_files(target: &str) -> Vec<PathBuf> {
    let dir = root().join("tests/fuzz/corpus").join(target);
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect()
}

/// Replays one corpus file through `load`; a panic fails the test, naming
/// `what` and the file.
fn replay<T>(what: &str, file: &Path, load: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(load))
        .unwrap_or_else(|_| panic!("{what} panicked on {}", file.display()))
}

/// The cargo-fuzz corpus (tests/fuzz/corpus/, kept minimised) replayed
/// through the loaders on every test run, without libFuzzer.
#[test]
fn the_cargo_fuzz_corpus_loads_without_panics() {
    let mut replayed = 0;
    for file in corpus_files("scene_toml") {
        let bytes = std::fs::read(&file).unwrap();
        if let Ok(text) = std::str::from_utf8(&bytes) {
            let load = || load_scene_str(text, Path::new("corpus.toml"));
            if let Ok(scene) = replay("the loader", &file, load) {
                assert_sane(&scene, text);
            }
        }
        replayed += 1;
    }
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    std::fs::write(dir.join("scene.toml"), mesh_scene()).unwrap();
    for file in corpus_files("obj_mesh") {
        std::fs::copy(&file, dir.join("fuzz.obj")).unwrap();
        let load = || load_scene(&dir.join("scene.toml"));
        if let Ok(scene) = replay("OBJ loading", &file, load) {
            assert_sane(&scene, &file.display().to_string());
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
    let n = iterations() / 3;
    let judge = |outcome, _: &str| outcome == Some(true);
    let (accepted, refused) = run_mutations(what, &seeds, &mut rng, n, prefix, target, judge);
    both_outcomes(what, accepted, refused);
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
    for (name, target) in harness::TARGETS {
        let mut replayed = 0;
        for file in corpus_files(name) {
            let bytes = std::fs::read(&file).unwrap();
            replay(name, &file, || target(&bytes));
            replayed += 1;
        }
        assert!(replayed > 0, "no corpus for {name}");
    }
}
