//! What the benchmark commands share in their output: `--json` and
//! `--quiet` (one option group, flattened into each), the folder a
//! benchmark writes into, its JSON written all or nothing, and file names
//! made from scene arguments and run labels.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use serde::Serialize;

use photonmap::image::{write_atomically, Image};

/// How a benchmark reports: a table on stdout, or its report as JSON; with
/// progress on stderr, or without.
#[derive(Args)]
pub struct BenchOutput {
    /// The report on stdout as JSON, not a table.
    #[arg(long)]
    pub json: bool,
    /// No progress on stderr.
    #[arg(long)]
    pub quiet: bool,
}

impl BenchOutput {
    /// Progress lines on stderr, unless --quiet.
    pub fn progress(&self) -> impl Fn(&str) {
        crate::cli::progress_lines(self.quiet)
    }

    /// The report on stdout: as JSON with --json, else as `table` prints it.
    pub fn print<T: Serialize>(&self, report: &T, table: impl FnOnce(&T)) -> Result<()> {
        if self.json {
            crate::cli::print_json(report)
        } else {
            table(report);
            Ok(())
        }
    }
}

/// The folder a benchmark writes into, made if missing: `out` (its --out),
/// else photonmap-out/<kind>/ or photonmap-out/<kind>/<name>/.
pub fn folder(out: Option<&Path>, kind: &str, name: Option<&str>) -> Result<PathBuf> {
    let dir = match (out, name) {
        (Some(out), _) => out.to_path_buf(),
        (None, Some(name)) => crate::cli::out_dir(kind).join(name),
        (None, None) => crate::cli::out_dir(kind),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    Ok(dir)
}

/// `value` as pretty JSON at `path`, written all or nothing.
pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    write_atomically(path, serde_json::to_string_pretty(value)?.as_bytes())?;
    Ok(())
}

/// The `index`th row's image, labelled `label`, as a PNG in `dir`
/// (`03_downsampling_4x4.png`), written all or nothing.
pub fn write_row_png(dir: &Path, index: usize, label: &str, image: &Image) -> Result<()> {
    let file = format!("{index:02}_{}.png", slug(label));
    write_atomically(&dir.join(file), &image.png_bytes()?)?;
    Ok(())
}

/// A scene argument's file stem: its name in output folders and references.
pub fn stem(scene: &Path) -> String {
    scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// A run's label as a file name: lower-case letters and digits, each other
/// run of characters one `_` ("+ downsampling 4x4" -> "downsampling_4x4").
pub fn slug(label: &str) -> String {
    label
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '_'
            }
        })
        .collect::<String>()
        .split('_')
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join("_")
}

/// This run's command line as a user would retype it (arguments with spaces
/// or quotes quoted), for a result file's heading.
pub fn command_line() -> String {
    let quoted = std::env::args().skip(1).map(|a| {
        if a.is_empty() || a.contains([' ', '"', '\'', '|']) {
            format!("\"{}\"", a.replace('"', "\\\""))
        } else {
            a
        }
    });
    std::iter::once("photonmap".to_string())
        .chain(quoted)
        .collect::<Vec<_>>()
        .join(" ")
}
