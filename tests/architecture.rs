//! The shape ARCHITECTURE.md promises, checked on the source itself:
//! dependencies run one way (render -> photon -> scene -> gpu, leaves below),
//! production code never imports the twins in src/reference/, every unsafe
//! block says why it is sound, no function is longer than a screen, and
//! main.rs only parses and dispatches.

mod common;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn sources() -> Vec<(String, String)> {
    let src = common::root().join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    files
        .into_iter()
        .map(|p| {
            let rel = p
                .strip_prefix(&src)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            (rel, std::fs::read_to_string(&p).unwrap())
        })
        .collect()
}

/// The code of a file with comments removed (line comments only: the project
/// writes no block comments).
fn code(text: &str) -> String {
    text.lines()
        .map(|l| match l.find("//") {
            Some(i) if !l[..i].contains('"') => &l[..i],
            _ => l,
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The library module a file belongs to (`photon/trace.rs` -> `photon`).
fn module_of(file: &str) -> Option<&str> {
    let first = file.split('/').next()?;
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
        "stress" | "regress" => 6,
        "reference" => 7,
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

#[test]
fn production_code_never_imports_the_twins() {
    let mut wrong = Vec::new();
    for (file, text) in sources() {
        if file.starts_with("reference/") {
            continue;
        }
        let code = code(&text);
        if code.contains("crate::reference") || code.contains("photonmap::reference") {
            wrong.push(file);
        }
    }
    assert!(wrong.is_empty(), "{wrong:?} import src/reference/");
}

#[test]
fn every_unsafe_block_says_why_it_is_sound() {
    let mut missing = Vec::new();
    for (file, text) in sources() {
        let lines: Vec<&str> = text.lines().collect();
        for (i, line) in lines.iter().enumerate() {
            let code = code(line);
            let is_unsafe = code.contains("unsafe {") || code.contains("unsafe impl");
            if !is_unsafe {
                continue;
            }
            if !file.starts_with("gpu/") {
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

#[test]
fn no_function_is_longer_than_a_screen() {
    let mut long = Vec::new();
    for (file, text) in sources() {
        let code = code(&text);
        let bytes = code.as_bytes();
        let mut search = 0;
        while let Some(found) = code[search..].find("fn ") {
            let start = search + found;
            search = start + 3;
            // A definition: an identifier after `fn `, then a body before any `;`.
            let boundary = start == 0
                || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_');
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
            if lines > 120 {
                long.push(format!("{file}: fn {name} ({lines} lines)"));
            }
        }
    }
    assert!(long.is_empty(), "functions over 120 lines: {long:?}");
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
