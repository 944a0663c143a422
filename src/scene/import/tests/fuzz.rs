//! The fuzz replay (cargo-fuzz needs a nightly compiler): every seed of
//! tests/fuzz_corpus/import/ (pbrt, xml, ply), and cheap mutations of each
//! (truncations, byte flips, spliced bytes), through the three parsers'
//! byte entry points must never panic. PHOTONMAP_FUZZ_ITERATIONS sets the
//! mutations per seed (default 300). The cargo-fuzz targets' minimised
//! corpora (tests/fuzz/corpus/{pbrt_scene,mitsuba_scene,ply_mesh}/) are
//! replayed through the targets' own code, tests/fuzz/import_harness.rs.

use super::*;
use crate::scene::import::{ply::parse_ply, NoFiles};

/// The cargo-fuzz targets' code, as their fuzz_targets/ include it.
#[path = "../../../../tests/fuzz/import_harness.rs"]
mod import_harness;

/// xorshift64: the mutations, reproducible.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: usize) -> usize {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 % n.max(1) as u64) as usize
    }
}

fn corpus(kind: &str) -> Vec<(PathBuf, Vec<u8>)> {
    let d = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_corpus/import")
        .join(kind);
    let mut v: Vec<_> = std::fs::read_dir(&d)
        .unwrap_or_else(|e| panic!("{}: {e}", d.display()))
        .map(|e| e.unwrap().path())
        .map(|p| {
            let b = std::fs::read(&p).unwrap();
            (p, b)
        })
        .collect();
    v.sort();
    assert!(!v.is_empty(), "{}", d.display());
    v
}

fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(3) {
        let n = b.len().max(1);
        match rng.below(4) {
            0 => b.truncate(rng.below(n)),
            1 if !b.is_empty() => {
                let i = rng.below(b.len());
                b[i] ^= 1 << rng.below(8);
            }
            2 if !b.is_empty() => {
                let i = rng.below(b.len());
                b[i] = b"\"[]<>/=$-. 0\n#e9"[rng.below(16)];
            }
            _ => {
                let (i, j) = (rng.below(n), rng.below(n));
                let piece: Vec<u8> = seed[i.min(seed.len())..j.max(i).min(seed.len())].to_vec();
                let at = rng.below(b.len() + 1);
                b.splice(at..at, piece);
            }
        }
    }
    b
}

fn run(kind: &str, parse: &dyn Fn(&Path, &[u8])) {
    let n: usize = std::env::var("PHOTONMAP_FUZZ_ITERATIONS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(300);
    let mut rng = Rng(0x1a2b_3c4d_5e6f_7081);
    for (path, seed) in corpus(kind) {
        parse(&path, &seed);
        for i in 0..seed.len().min(64) {
            parse(&path, &seed[..seed.len() * i / 64]);
        }
        for _ in 0..n {
            parse(&path, &mutate(&seed, &mut rng));
        }
    }
}

fn scene(format: Format) -> impl Fn(&Path, &[u8]) {
    move |path: &Path, bytes: &[u8]| {
        for lenient in [false, true] {
            let opts = ImportOptions {
                lenient,
                defines: vec![("spp".into(), "4".into())],
            };
            if let Ok(c) = convert_bytes(format, bytes, path, &NoFiles, &opts) {
                let _ = load_scene_str(&c.toml, path);
            }
        }
    }
}

#[test]
fn pbrt_never_panics() {
    run("pbrt", &scene(Format::Pbrt));
}

#[test]
fn mitsuba_never_panics() {
    run("xml", &scene(Format::Mitsuba));
}

#[test]
fn ply_never_panics() {
    run("ply", &|_, b| {
        let _ = parse_ply(b);
    });
}

/// The cargo-fuzz corpora of the importers' targets, each file through its
/// target, without libFuzzer: no panic, and each corpus has accepted inputs.
#[test]
fn the_cargo_fuzz_corpora_of_the_importers_replay_without_panics() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz/corpus");
    for (name, target) in import_harness::TARGETS {
        let dir = root.join(name);
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
            .map(|e| e.unwrap().path())
            .collect();
        files.sort();
        assert!(!files.is_empty(), "no corpus for {name}");
        let mut accepted = 0;
        for file in &files {
            let bytes = std::fs::read(file).unwrap();
            let outcome = std::panic::catch_unwind(|| target(&bytes))
                .unwrap_or_else(|_| panic!("{name} panicked on {}", file.display()));
            accepted += usize::from(outcome == Some(true));
        }
        assert!(
            accepted > 0,
            "{name}: none of {} files accepted",
            files.len()
        );
    }
}
