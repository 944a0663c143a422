//! The subcommands, one module each, and what they share: option groups
//! (`args`), output checks, and the GPU.

pub mod accuracy;
pub mod args;
pub mod bench;
pub mod compare;
pub mod info;
pub mod photons;
pub mod reference;
pub mod render;
pub mod scenes;
pub mod tables;

use std::path::Path;

use anyhow::{bail, Result};
use photonmap::gpu::{Gpu, Platform};

/// The GPU on the chosen platform.
pub fn gpu(platform: Platform) -> Result<Gpu> {
    Ok(Gpu::new(platform)?)
}

/// Refuses an output path with the wrong extension or in a missing folder,
/// before any work is done.
pub fn check_output(path: &Path, extension: &str, flag: &str) -> Result<()> {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if !ext.eq_ignore_ascii_case(extension) {
        bail!(
            "{flag} {}: the file name must end in .{extension}",
            path.display()
        );
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if !dir.is_dir() {
        bail!(
            "{flag} {}: the folder {} does not exist",
            path.display(),
            dir.display()
        );
    }
    Ok(())
}

/// Where a command writes when no `--out` is given: photonmap-out/<kind>/
/// under the current folder (git ignores it in this repository), never the
/// committed results or references.
pub fn out_dir(kind: &str) -> std::path::PathBuf {
    std::path::Path::new("photonmap-out").join(kind)
}

/// Prints `value` as pretty JSON on stdout.
pub fn print_json(value: &impl serde::Serialize) -> Result<()> {
    println!("{}", serde_json::to_string_pretty(value)?);
    Ok(())
}

/// Progress lines on stderr unless quiet.
pub fn progress_lines(quiet: bool) -> impl Fn(&str) {
    move |m: &str| {
        if !quiet {
            eprintln!("{m}");
        }
    }
}
