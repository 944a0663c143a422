//! The subcommands, one module each, and what they share: option groups
//! (`args`), output checks, and the GPU. The benchmarks (`bench ...`) and
//! the two commands that measure against references (`reference`, `tables`)
//! live together in `bench/`.

pub mod args;
pub mod bench;
pub mod ci_report;
pub mod compare;
pub mod convert;
pub mod convert_scene;
pub mod info;
pub mod merge;
pub mod merge_tiles;
pub mod photons;
pub mod progress;
pub mod regress;
pub mod render;
pub mod scenes;

pub use bench::{reference, tables};

use std::path::Path;

use anyhow::{bail, Result};
use photonmap::gpu::{Gpu, Platform};

static THREADS: std::sync::OnceLock<Option<u32>> = std::sync::OnceLock::new();

/// `--threads N`: llvmpipe reads LP_NUM_THREADS when a context is made, so it
/// is set before any (main is still single-threaded here).
pub fn set_threads(threads: Option<u32>) {
    if let Some(n) = threads {
        std::env::set_var("LP_NUM_THREADS", n.to_string());
    }
    let _ = THREADS.set(threads);
}

/// The GPU on the chosen platform.
pub fn gpu(platform: Platform) -> Result<Gpu> {
    let gpu = Gpu::new(platform)?;
    if let Some(Some(n)) = THREADS.get() {
        let renderer = gpu.capabilities().gl_renderer;
        if !renderer.contains("llvmpipe") {
            eprintln!("note: --threads {n} is for llvmpipe; {renderer} ignores it");
        }
    }
    Ok(gpu)
}

/// Before any command: the signal handlers (src/interrupt.rs) and llvmpipe's threads.
pub fn prepare(threads: Option<u32>) {
    if let Err(e) = photonmap::interrupt::install() {
        eprintln!("note: SIGINT and SIGTERM will end the program at once: {e}");
    }
    set_threads(threads);
}

/// The provenance's driver part.
pub fn with_driver(
    mut p: photonmap::provenance::Provenance,
    gpu: &Gpu,
) -> photonmap::provenance::Provenance {
    let caps = gpu.capabilities();
    p.platform = caps.platform;
    p.renderer = caps.gl_renderer;
    p.gl_version = caps.gl_version;
    p
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

/// The exit of a command that failed: its error and every cause, on stderr;
/// 128 + the signal after SIGINT or SIGTERM (130, 143), as shells expect.
pub fn fail(e: anyhow::Error) -> std::process::ExitCode {
    // As `{e:#}` writes the chain, with options named by their flags.
    let causes: Vec<String> = e
        .chain()
        .map(|c| match c.downcast_ref() {
            Some(photonmap::error::Error::OutOfRange {
                option,
                value,
                allowed,
            }) => format!("{} {value}: {allowed}", args::flag_of(option)),
            _ => c.to_string(),
        })
        .collect();
    eprintln!("error: {}", causes.join(": "));
    let signal = e.chain().find_map(|c| match c.downcast_ref() {
        Some(
            photonmap::error::Error::Interrupted { signal }
            | photonmap::error::Error::InterruptedAfterWriting { signal, .. },
        ) => Some(*signal),
        _ => None,
    });
    match signal {
        Some(s) => std::process::ExitCode::from((128 + s) as u8),
        None => std::process::ExitCode::FAILURE,
    }
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
