//! The book in docs/ kept in step with the program and the repository, with
//! no GL context (`--help` opens none):
//! - docs/src/reference/cli.md is the program's own `--help`, for the top
//!   command and every subcommand, nested ones included (`bench accuracy`);
//!   `UPDATE_DOCS=1 cargo test --release --test docs_sync` rewrites it;
//! - every `{{#include PATH}}` in the book (but an escaped `\{{#include`)
//!   names a file that exists, and a line range or anchor that the file has;
//! - every chapter SUMMARY.md lists exists, and every relative link or image
//!   in the book and in README.md points at a file that exists.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const CLI_PAGE: &str = "docs/src/reference/cli.md";
const UPDATE: &str = "UPDATE_DOCS=1 cargo test --release --test docs_sync";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// `photonmap ARGS --help`, uncoloured, each line's trailing blanks removed.
fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_photonmap"))
        .args(args)
        .arg("--help")
        .env("NO_COLOR", "1")
        .env_remove("CLICOLOR_FORCE")
        .env_remove("COLUMNS")
        .stdin(Stdio::null())
        .output()
        .expect("the photonmap binary runs");
    assert!(
        out.status.success(),
        "photonmap {} --help failed: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("help is UTF-8");
    let lines: Vec<&str> = text.lines().map(str::trim_end).collect();
    lines.join("\n").trim_end().to_string()
}

/// The names in a help text's `Commands:` list, in its order, less `help`.
fn subcommands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| *l != "Commands:")
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter(|l| l.starts_with("  ") && !l[2..].starts_with(' '))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != "help")
        .map(str::to_string)
        .collect()
}

/// Every command path, depth first in the order `--help` lists them.
fn commands(path: &mut Vec<String>, out: &mut Vec<(Vec<String>, String)>) {
    let args: Vec<&str> = path.iter().map(String::as_str).collect();
    let text = help(&args);
    let subs = subcommands(&text);
    out.push((path.clone(), text));
    for sub in subs {
        path.push(sub);
        commands(path, out);
        path.pop();
    }
}

fn cli_page() -> String {
    let mut all = Vec::new();
    commands(&mut Vec::new(), &mut all);
    assert!(
        all.len() > 10,
        "found only {} commands: is the Commands: list still parsed?",
        all.len()
    );
    let mut page = String::from(
        "# Command reference\n\n\
         Every command's `--help`, as the program prints it. This page is generated:\n\
         do not edit it by hand; `UPDATE_DOCS=1 cargo test --release --test docs_sync`\n\
         writes it again from the binary.\n",
    );
    for (path, text) in all {
        let name = std::iter::once("photonmap".to_string())
            .chain(path)
            .collect::<Vec<_>>()
            .join(" ");
        page.push_str(&format!("\n## `{name}`\n\n```text\n{text}\n```\n"));
    }
    page
}

/// Every command that a `Commands:` list names, at every level, says what
/// it does on its line (clap prints a bare name for a command without one).
#[test]
fn every_command_is_described_where_its_parent_lists_it() {
    let mut all = Vec::new();
    commands(&mut Vec::new(), &mut all);
    let mut bare = Vec::new();
    for (path, text) in &all {
        let listed = text
            .lines()
            .skip_while(|l| *l != "Commands:")
            .skip(1)
            .take_while(|l| !l.trim().is_empty())
            .filter(|l| l.starts_with("  ") && !l[2..].starts_with(' '));
        for line in listed {
            if line.split_whitespace().nth(1).is_none() {
                bare.push(format!("photonmap {} {}", path.join(" "), line.trim()));
            }
        }
    }
    assert!(bare.is_empty(), "listed with no description: {bare:?}");
}

#[test]
fn the_command_reference_is_the_programs_own_help() {
    let want = cli_page();
    let path = root().join(CLI_PAGE);
    if std::env::var_os("UPDATE_DOCS").is_some_and(|v| v == "1") {
        std::fs::write(&path, &want).expect("write the command reference");
        return;
    }
    let have = std::fs::read_to_string(&path).unwrap_or_default();
    if have == want {
        return;
    }
    let first = have
        .lines()
        .zip(want.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| have.lines().count().min(want.lines().count()));
    panic!(
        "{CLI_PAGE} is not the program's --help (first difference at line {}:\n  \
         file:    {:?}\n  program: {:?})\nrerun with `{UPDATE}` to rewrite it",
        first + 1,
        have.lines().nth(first).unwrap_or("<end of file>"),
        want.lines().nth(first).unwrap_or("<end of help>"),
    );
}

fn markdown_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir)
        .expect("read a docs folder")
        .flatten()
    {
        let p = e.path();
        if p.is_dir() {
            markdown_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "md") {
            out.push(p);
        }
    }
}

fn book_chapters() -> Vec<(PathBuf, String)> {
    let mut files = Vec::new();
    markdown_files(&root().join("docs/src"), &mut files);
    files.sort();
    assert!(!files.is_empty(), "docs/src holds no chapter");
    files
        .into_iter()
        .map(|p| {
            let text = std::fs::read_to_string(&p).expect("read a chapter");
            (p, text)
        })
        .collect()
}

fn shown(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}

/// What a `{{#include ...}}` asks for, checked against the file it names.
fn check_include(chapter: &Path, spec: &str) -> Result<(), String> {
    let mut parts = spec.split(':');
    let file = parts.next().unwrap_or_default().trim();
    let rest: Vec<&str> = parts.map(str::trim).collect();
    let target = chapter.parent().expect("a chapter's folder").join(file);
    let text = std::fs::read_to_string(&target)
        .map_err(|e| format!("{{{{#include {spec}}}}}: {}: {e}", shown(&target)))?;
    let lines = text.lines().count();
    let number = |s: &str| -> Result<Option<usize>, String> {
        if s.is_empty() {
            return Ok(None);
        }
        s.parse::<usize>()
            .map(Some)
            .map_err(|_| format!("{{{{#include {spec}}}}}: {s:?} is not a line number"))
    };
    match rest.as_slice() {
        [] => Ok(()),
        [one] if one.parse::<usize>().is_err() => {
            let (start, end) = (format!("ANCHOR: {one}"), format!("ANCHOR_END: {one}"));
            if text.lines().any(|l| l.contains(&start)) && text.lines().any(|l| l.contains(&end)) {
                Ok(())
            } else {
                Err(format!(
                    "{{{{#include {spec}}}}}: {} has no anchor {one:?}",
                    shown(&target)
                ))
            }
        }
        [one] => check_range(spec, &target, number(one)?, number(one)?, lines),
        [a, b] => check_range(spec, &target, number(a)?, number(b)?, lines),
        _ => Err(format!("{{{{#include {spec}}}}}: too many ':'")),
    }
}

fn check_range(
    spec: &str,
    target: &Path,
    start: Option<usize>,
    end: Option<usize>,
    lines: usize,
) -> Result<(), String> {
    let (s, e) = (start.unwrap_or(1), end.unwrap_or(lines));
    if s >= 1 && s <= e && e <= lines {
        Ok(())
    } else {
        Err(format!(
            "{{{{#include {spec}}}}}: lines {s}..{e} of {} ({lines} lines)",
            shown(target)
        ))
    }
}

#[test]
fn every_include_in_the_book_names_a_file_that_exists() {
    let mut bad = Vec::new();
    let mut count = 0;
    for (chapter, text) in book_chapters() {
        let pieces: Vec<&str> = text.split("{{#include ").collect();
        for (before, piece) in pieces.iter().zip(pieces.iter().skip(1)) {
            // mdBook leaves `\{{#include ...}}` as text.
            if before.ends_with('\\') {
                continue;
            }
            let Some(spec) = piece.split("}}").next() else {
                continue;
            };
            count += 1;
            if let Err(e) = check_include(&chapter, spec) {
                bad.push(format!("{}: {e}", shown(&chapter)));
            }
        }
    }
    assert!(count > 0, "the book includes no file");
    assert!(
        bad.is_empty(),
        "includes that name no file:\n{}",
        bad.join("\n")
    );
}

/// The targets of a Markdown text's inline links and images, `](target)`,
/// outside code.
fn link_targets(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut fenced = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        }
        if fenced || line.starts_with("    ") {
            continue;
        }
        for piece in line.split("](").skip(1) {
            if let Some(end) = piece.find(')') {
                out.push(piece[..end].to_string());
            }
        }
    }
    out
}

fn check_links(file: &Path, text: &str, bad: &mut Vec<String>) {
    for target in link_targets(text) {
        let path = target.split('#').next().unwrap_or_default();
        if path.is_empty() || target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let resolved = file.parent().expect("a file's folder").join(path);
        if !resolved.exists() {
            bad.push(format!("{}: ({target})", shown(file)));
        }
    }
}

#[test]
fn every_chapter_and_link_points_at_a_file_that_exists() {
    let mut bad = Vec::new();
    for (chapter, text) in book_chapters() {
        check_links(&chapter, &text, &mut bad);
    }
    let readme = root().join("README.md");
    let text = std::fs::read_to_string(&readme).expect("read README.md");
    check_links(&readme, &text, &mut bad);
    assert!(bad.is_empty(), "links to nothing:\n{}", bad.join("\n"));
}
