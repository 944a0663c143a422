//! The source files the checks read, and their code without comments and
//! literals.

use std::path::Path;

use crate::common;

pub fn rust_files(dir: &Path, out: &mut Vec<String>) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            let rel = p.strip_prefix(common::root()).unwrap();
            out.push(rel.to_string_lossy().replace('\\', "/"));
        }
    }
}

/// Every Rust file under `top` (`src` or `tests`), by its path from the
/// repository root, with its text.
pub fn sources_in(top: &str) -> Vec<(String, String)> {
    let mut files = Vec::new();
    rust_files(&common::root().join(top), &mut files);
    files.sort();
    files
        .into_iter()
        .map(|f| {
            let text = std::fs::read_to_string(common::root().join(&f)).unwrap();
            (f, text)
        })
        .collect()
}

pub fn sources() -> Vec<(String, String)> {
    sources_in("src")
}

pub fn src_and_tests() -> Vec<(String, String)> {
    let mut all = sources();
    all.extend(sources_in("tests"));
    all
}

/// Where the comment or the string or character literal starting at `i` ends
/// (one past it), if one starts there.
pub fn literal_end(c: &[char], i: usize) -> Option<usize> {
    let at = |k: usize| c.get(k).copied().unwrap_or('\0');
    let ident = |ch: char| ch.is_alphanumeric() || ch == '_';
    let find = |from: usize, pat: &[char]| {
        (from..c.len())
            .find(|&k| c[k..].starts_with(pat))
            .map_or(c.len(), |k| k + pat.len())
    };
    match (at(i), at(i + 1)) {
        ('/', '/') => Some(find(i, &['\n']) - 1),
        ('/', '*') => {
            let (mut depth, mut k) = (0, i);
            while k < c.len() {
                if c[k..].starts_with(&['/', '*']) {
                    depth += 1;
                    k += 2;
                } else if c[k..].starts_with(&['*', '/']) {
                    depth -= 1;
                    k += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    k += 1;
                }
            }
            Some(k)
        }
        ('"', _) => {
            let mut k = i + 1;
            while k < c.len() && c[k] != '"' {
                k += if c[k] == '\\' { 2 } else { 1 };
            }
            Some((k + 1).min(c.len()))
        }
        ('r', '"' | '#')
            if i == 0 || !ident(at(i - 1)) || (at(i - 1) == 'b' && !ident(at(i - 2))) =>
        {
            let hashes = (i + 1..c.len()).take_while(|&k| c[k] == '#').count();
            if at(i + 1 + hashes) != '"' {
                return None;
            }
            let close: Vec<char> = std::iter::once('"').chain(vec!['#'; hashes]).collect();
            Some(find(i + 2 + hashes, &close))
        }
        ('\'', '\\') => Some(find(i + 3, &['\''])),
        ('\'', _) if at(i + 2) == '\'' => Some(i + 3),
        _ => None,
    }
}

/// The code of a file: every comment and the inside of every string and
/// character literal turned into spaces (newlines kept, so lines still
/// count), and any other non-ASCII character too, so what is left is ASCII.
pub fn code(text: &str) -> String {
    let c: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(c.len());
    let mut i = 0;
    while i < c.len() {
        if let Some(end) = literal_end(&c, i) {
            out.extend(
                c[i..end]
                    .iter()
                    .map(|&ch| if ch == '\n' { ch } else { ' ' }),
            );
            i = end;
        } else {
            out.push(if c[i].is_ascii() { c[i] } else { ' ' });
            i += 1;
        }
    }
    out
}

pub fn ident_byte(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b == b'_'
}
