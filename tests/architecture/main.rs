//! The shape ARCHITECTURE.md promises, checked on the source itself:
//! dependencies between modules run one way (render -> photon -> scene -> gpu,
//! leaves below), no source file imports a file that imports it back (in src/
//! and tests/), the twins in src/twins/ are compiled only for tests, every
//! unsafe block says why it is sound, no function is longer than a screen, no
//! file in src/ is longer than 800 lines, main.rs only parses and
//! dispatches, and only test modules name the source tree's folder.

#[path = "../common/mod.rs"]
mod common;
mod imports;
mod source;

use std::collections::{BTreeMap, BTreeSet};

use imports::{crate_roots, file_cycles};
use source::{code, ident_byte, sources, src_and_tests};

/// Cycles of file imports that exist today, each the set of files that reach
/// one another. Each is to be broken: the test fails on any cycle not listed
/// here and on any listed one that no longer exists as written, so this list
/// only shrinks, to empty.
const KNOWN_CYCLES: &[&[&str]] = &[];

/// The most lines a file in src/ may have.
const MAX_FILE_LINES: usize = 800;

/// Files in src/ longer than `MAX_FILE_LINES` today. Each is to be split: the
/// test fails when a listed file is no longer too long (remove it here), so
/// this list only shrinks, to empty.
const OVERSIZED_FILES: &[&str] = &[];

/// The most lines a function may have: a screen.
const MAX_FUNCTION_LINES: usize = 120;

/// Test functions longer than `MAX_FUNCTION_LINES` today (`file: name`). Each
/// is to be split: the test fails when a listed one is no longer too long
/// (remove it here), so this list only shrinks, to empty.
const LONG_TEST_FUNCTIONS: &[&str] = &[
    "tests/gpu/adaptive.rs: adaptive_sppm_computes_what_full_sppm_does_and_fills_as_its_twin",
    "tests/gpu/igi.rs: interleaving_and_upsampling_equal_their_cpu_twins",
];

/// The library module a file belongs to (`src/photon/trace.rs` -> `photon`).
fn module_of(file: &str) -> Option<&str> {
    let first = file.strip_prefix("src/")?.split('/').next()?;
    let m = first.trim_end_matches(".rs");
    (!matches!(m, "main" | "cli" | "lib")).then_some(m)
}

/// Which library modules each module uses through `crate::`.
fn imports() -> BTreeMap<String, BTreeSet<String>> {
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (file, text) in sources() {
        let Some(m) = module_of(&file) else { continue };
        let entry = graph.entry(m.to_string()).or_default();
        let code = code(&text);
        for (i, _) in code.match_indices("crate::") {
            let rest = &code[i + "crate::".len()..];
            let used: String = rest
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !used.is_empty() && used != m && used != "Result" && used != "Error" {
                entry.insert(used);
            }
        }
    }
    graph
}

#[test]
fn dependencies_run_one_way() {
    // Rank: a module may use modules of a lower rank only.
    let rank = |m: &str| match m {
        "error" | "layout" | "random" | "sampling" | "timing" | "provenance" => 0,
        "image" | "interrupt" => 1,
        "metrics" | "gpu" => 2,
        "scene" => 3,
        "photon" => 4,
        "render" => 5,
        "bench" | "regress" => 6,
        "twins" => 7,
        other => panic!("a module ARCHITECTURE.md does not place: {other}"),
    };
    let mut wrong = Vec::new();
    for (m, used) in imports() {
        for u in used {
            if rank(&u) >= rank(&m) {
                wrong.push(format!("{m} uses {u}"));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "dependencies against the direction: {wrong:?}"
    );
}

/// The twins exist only with the `twins` feature, which only the package's
/// own tests turn on, so production code that named them would not build
/// (`cargo check --release --lib --bins` in CI proves it); and no production
/// file names them.
#[test]
fn the_twins_are_compiled_only_for_tests() {
    let lib = std::fs::read_to_string(common::root().join("src/lib.rs")).unwrap();
    let lines: Vec<&str> = lib.lines().collect();
    let decl = lines
        .iter()
        .position(|l| l.trim() == "pub mod twins;")
        .expect("src/lib.rs declares `pub mod twins;`");
    let attributes = lines[..decl]
        .iter()
        .rev()
        .take_while(|l| l.trim_start().starts_with("#[") || l.trim_start().starts_with("//"));
    assert!(
        attributes
            .into_iter()
            .any(|l| l.trim() == "#[cfg(feature = \"twins\")]"),
        "`pub mod twins;` in src/lib.rs must be behind #[cfg(feature = \"twins\")]"
    );
    let manifest = std::fs::read_to_string(common::root().join("Cargo.toml")).unwrap();
    let manifest: toml::Table = toml::from_str(&manifest).unwrap();
    let features = manifest["features"].as_table().expect("[features]");
    assert!(
        features.contains_key("twins"),
        "Cargo.toml has no twins feature"
    );
    let default = features.get("default").and_then(|d| d.as_array());
    assert!(
        !default.is_some_and(|d| d.iter().any(|f| f.as_str() == Some("twins"))),
        "the twins feature must not be a default"
    );
    let mut wrong = Vec::new();
    for (file, text) in sources() {
        if file.starts_with("src/twins/") {
            continue;
        }
        let code = code(&text);
        if ["crate::twins", "photonmap::twins", "super::twins"]
            .iter()
            .any(|p| code.contains(p))
        {
            wrong.push(file);
        }
    }
    assert!(wrong.is_empty(), "{wrong:?} use src/twins/");
}

/// Whether a line of code opens an unsafe block or an unsafe impl.
fn opens_unsafe(line: &str) -> bool {
    line.match_indices("unsafe").any(|(i, _)| {
        let word = i == 0 || !ident_byte(line.as_bytes()[i - 1]);
        let rest = line[i + "unsafe".len()..].trim_start();
        word && (rest.starts_with('{') || rest.starts_with("impl "))
    })
}

#[test]
fn every_unsafe_block_says_why_it_is_sound() {
    let mut missing = Vec::new();
    for (file, text) in src_and_tests() {
        let lines: Vec<&str> = text.lines().collect();
        for (i, code) in code(&text).lines().enumerate() {
            if !opens_unsafe(code) {
                continue;
            }
            if file.starts_with("src/") && !file.starts_with("src/gpu/") {
                missing.push(format!("{file}:{}: unsafe outside src/gpu/", i + 1));
            }
            let above = &lines[i.saturating_sub(4)..=i];
            if !above.iter().any(|l| l.contains("SAFETY")) {
                missing.push(format!("{file}:{}", i + 1));
            }
        }
    }
    assert!(
        missing.is_empty(),
        "unsafe without a SAFETY comment: {missing:#?}"
    );
}

/// The functions of a file's code over `limit` lines, with their lengths.
fn long_functions(code: &str, limit: usize) -> Vec<(String, usize)> {
    let bytes = code.as_bytes();
    let mut long = Vec::new();
    let mut search = 0;
    while let Some(found) = code[search..].find("fn ") {
        let start = search + found;
        search = start + 3;
        // A definition: an identifier after `fn `, then a body before any `;`.
        let boundary =
            start == 0 || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_');
        let name: String = code[start + 3..]
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if !boundary || name.is_empty() {
            continue;
        }
        let (Some(open), semi) = (code[start..].find('{'), code[start..].find(';')) else {
            continue;
        };
        if semi.is_some_and(|s| s < open) {
            continue;
        }
        let mut depth = 0;
        let mut end = start + open;
        for (j, b) in bytes[start + open..].iter().enumerate() {
            depth += match b {
                b'{' => 1,
                b'}' => -1,
                _ => 0,
            };
            if depth == 0 {
                end = start + open + j;
                break;
            }
        }
        let lines = code[start..=end].lines().count();
        if lines > limit {
            long.push((name, lines));
        }
    }
    long
}

/// Nothing of `what` is over `limit` lines but what the allow-list `list`
/// names, and the list names nothing (`shrunk`) that no longer is: it only
/// shrinks.
fn assert_only_the_allowed_are_over(
    (what, limit): (&str, usize),
    over: &[String],
    (list, shrunk): (&str, &[&&str]),
) {
    assert!(over.is_empty(), "{what} over {limit} lines: {over:?}");
    assert!(
        shrunk.is_empty(),
        "no longer over {limit} lines (or gone): remove {shrunk:?} from {list}"
    );
}

#[test]
fn no_function_is_longer_than_a_screen() {
    let mut long = Vec::new();
    let mut known_long = BTreeSet::new();
    for (file, text) in src_and_tests() {
        for (name, lines) in long_functions(&code(&text), MAX_FUNCTION_LINES) {
            let id = format!("{file}: {name}");
            if LONG_TEST_FUNCTIONS.contains(&id.as_str()) {
                known_long.insert(id);
            } else {
                long.push(format!("{file}: fn {name} ({lines} lines)"));
            }
        }
    }
    let shrunk: Vec<_> = LONG_TEST_FUNCTIONS
        .iter()
        .filter(|f| !known_long.contains(**f))
        .collect();
    assert_only_the_allowed_are_over(
        ("functions", MAX_FUNCTION_LINES),
        &long,
        ("LONG_TEST_FUNCTIONS", &shrunk),
    );
}

#[test]
fn no_source_file_is_too_long() {
    let mut too_long = Vec::new();
    let mut lengths = BTreeMap::new();
    for (file, text) in sources() {
        let lines = text.lines().count();
        if lines > MAX_FILE_LINES && !OVERSIZED_FILES.contains(&file.as_str()) {
            too_long.push(format!("{file} ({lines} lines)"));
        }
        lengths.insert(file, lines);
    }
    let shrunk: Vec<_> = OVERSIZED_FILES
        .iter()
        .filter(|f| lengths.get(**f).is_none_or(|&n| n <= MAX_FILE_LINES))
        .collect();
    assert_only_the_allowed_are_over(
        ("files", MAX_FILE_LINES),
        &too_long,
        ("OVERSIZED_FILES", &shrunk),
    );
}

#[test]
fn only_test_modules_name_the_source_tree() {
    // `env!("CARGO_MANIFEST_DIR")` bakes the build's folder into the
    // binary: an installed photonmap must not need its source tree beside
    // it. Unit tests may, in a `tests` folder declared `#[cfg(test)]`.
    let mut outside = Vec::new();
    for (file, text) in sources() {
        if !text.contains("CARGO_MANIFEST_DIR") {
            continue;
        }
        let Some((parent, _)) = file.split_once("/tests/") else {
            outside.push(file);
            continue;
        };
        let declared = [format!("{parent}/mod.rs"), format!("{parent}.rs")]
            .iter()
            .filter_map(|d| std::fs::read_to_string(common::root().join(d)).ok())
            .any(|t| t.contains("#[cfg(test)]\nmod tests;"));
        if !declared {
            outside.push(file);
        }
    }
    assert!(
        outside.is_empty(),
        "CARGO_MANIFEST_DIR outside a #[cfg(test)] tests module: {outside:?}"
    );
}

#[test]
fn main_only_parses_and_dispatches() {
    let main = std::fs::read_to_string(common::root().join("src/main.rs")).unwrap();
    assert!(
        main.lines().count() <= 60,
        "src/main.rs has {} lines",
        main.lines().count()
    );
}

#[test]
fn no_file_imports_a_file_that_imports_it_back() {
    let cycles = file_cycles(&crate_roots());
    let known: BTreeSet<Vec<String>> = KNOWN_CYCLES
        .iter()
        .map(|c| {
            let mut files: Vec<String> = c.iter().map(|f| f.to_string()).collect();
            files.sort();
            files
        })
        .collect();
    let mut new = Vec::new();
    let mut shrunk = Vec::new();
    for (files, paths) in &cycles {
        if known.contains(files) {
            continue;
        }
        let paths: Vec<String> = paths.iter().map(|p| p.join(" -> ")).collect();
        let found = format!("{files:?}, through\n    {}", paths.join("\n    "));
        match known.iter().find(|k| files.iter().all(|f| k.contains(f))) {
            Some(was) => shrunk.push(format!("{found}\n  (listed as {was:?})")),
            None => new.push(found),
        }
    }
    let gone: Vec<_> = known.iter().filter(|c| !cycles.contains_key(*c)).collect();
    assert!(
        new.is_empty(),
        "files that import one another (break the cycle):\n{}",
        new.join("\n")
    );
    assert!(
        shrunk.is_empty(),
        "cycles smaller than KNOWN_CYCLES lists them (list what is left):\n{}",
        shrunk.join("\n")
    );
    assert!(
        gone.is_empty(),
        "cycles in KNOWN_CYCLES that no longer exist as listed (remove them): {gone:?}"
    );
}
