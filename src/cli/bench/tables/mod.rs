//! `photonmap tables`: every table and figure of the paper this machine can
//! regenerate, beside the paper's own numbers, into results/<renderer>/.
//! What the report holds is in `report`, the renders behind Table 1,
//! section 3.3 and figure 8 in `renders`, Table 2's instruction counts in
//! `kernels`, the Markdown and CSV in `markdown`, and the files kept until
//! they are all written at once in `staged`; here are the command and its
//! run.

mod kernels;
mod markdown;
mod renders;
mod report;
mod staged;

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;

use photonmap::bench::build::{bench_size, paper_grid};
use photonmap::gpu::{Gpu, Platform};

use super::output::BenchOutput;
use renders::{montage, TablesRun};
use report::TablesReport;
use staged::Staged;

pub(crate) use renders::table1_options;

/// Reproduce the paper's tables and figures into results/<renderer>/ (or --out).
#[derive(Args)]
pub struct TablesArgs {
    /// Output folder (default: results/<renderer>/).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// A reduced run for CI: quarter resolution, one run, fewer sizes and modes.
    #[arg(long)]
    pub quick: bool,
    /// The paper's 2003 constraints: a random-number texture, read-back
    /// before routing, float addressing, no compaction, the faithful sort
    /// passes, no projection maps, and stencil routing's m = 16.
    #[arg(long)]
    pub faithful: bool,
    /// Stencil routing's m, each cell holding m x m photons (1..=16; default
    /// 4, or 16 with --faithful).
    #[arg(long, value_name = "M", value_parser = crate::cli::args::in_range(1, 16))]
    pub stencil_m: Option<u32>,
    /// Table 1 and figure 7 only (no section 3.3, pass counts, figure 8 or
    /// Table 2).
    #[arg(long)]
    pub table1_only: bool,
    /// Runs per Table 1 cell, median and spread quoted (1..=20).
    #[arg(long, default_value_t = 3, value_parser = crate::cli::args::in_range(1, 20))]
    pub runs: u32,
    #[command(flatten)]
    pub output: BenchOutput,
}

pub fn run(a: &TablesArgs, platform: Platform) -> Result<()> {
    let gpu = crate::cli::gpu(platform)?;
    let (report, dir) = run_tables(&gpu, a, &a.output.progress())?;
    a.output.print(&report, |r| {
        print!("{}", markdown::document(r));
        eprintln!("wrote {}", dir.display());
    })
}

/// photonmap-out/tables/<first word of the renderer, lower case>/: the
/// committed results/ change only when named with --out.
pub fn default_out(renderer: &str) -> PathBuf {
    let word: String = renderer
        .split_whitespace()
        .next()
        .unwrap_or("unknown")
        .chars()
        .filter(|c| c.is_ascii_alphanumeric() || *c == '-' || *c == '_')
        .collect::<String>()
        .to_lowercase();
    crate::cli::out_dir("tables").join(if word.is_empty() {
        "unknown".into()
    } else {
        word
    })
}

pub fn run_tables(
    gpu: &Gpu,
    o: &TablesArgs,
    progress: &dyn Fn(&str),
) -> Result<(TablesReport, PathBuf)> {
    let caps = gpu.capabilities();
    let out = o
        .out
        .clone()
        .unwrap_or_else(|| default_out(&caps.gl_renderer));
    if o.table1_only && o.out.is_none() {
        anyhow::bail!(
            "--table1-only needs --out: Table 1 alone would replace the full run's tables.md in {}",
            out.display()
        );
    }
    let dirs: &[&str] = if o.table1_only {
        &["figure7"]
    } else {
        &["figure7", "figure8"]
    };
    for dir in dirs {
        std::fs::create_dir_all(out.join(dir))
            .with_context(|| format!("creating {}", out.display()))?;
    }
    let stencil_m = o.stencil_m.unwrap_or(if o.faithful { 16 } else { 4 });
    let run = TablesRun {
        gpu,
        scale: if o.quick { 4 } else { 1 },
        runs: if o.quick { 1 } else { o.runs },
        quick: o.quick,
        faithful: o.faithful,
        stencil_m,
        out: &out,
        progress,
        staged: Staged::default(),
    };
    let (table1, totals, figure7_rows) = run.table1()?;
    run.staged
        .png(out.join("figure7.png"), &montage(&figure7_rows))?;
    let (mut convergence, mut passes, mut figure8) = (Vec::new(), Vec::new(), None);
    if !o.table1_only {
        convergence = run.section_3_3()?;
        for k in 10..=(if o.quick { 12 } else { 20 }) {
            progress(&format!("Passes: n = 2^{k}"));
            passes.push(bench_size(gpu, 1 << k, &paper_grid(), stencil_m)?);
        }
        figure8 = Some(run.figure8()?);
        progress("Table 2: SPIR-V instruction counts");
    }
    let report = TablesReport {
        renderer: caps.gl_renderer,
        gl_version: caps.gl_version,
        cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
        quick: o.quick,
        faithful: o.faithful,
        stencil_m,
        table1_only: o.table1_only,
        image_scale: if o.quick {
            "1/4 of the paper's resolution".into()
        } else {
            "the paper's resolution".into()
        },
        runs: run.runs,
        command: format!(
            "photonmap tables{}{}{}{}",
            if o.quick { " --quick" } else { "" },
            if o.faithful { " --faithful" } else { "" },
            o.stencil_m
                .map_or(String::new(), |m| format!(" --stencil-m {m}")),
            if o.table1_only { " --table1-only" } else { "" }
        ),
        table1,
        totals,
        convergence,
        passes,
        figure7: "figure7.png".into(),
        figure8,
        table2: if o.table1_only {
            Err("not run (--table1-only)".into())
        } else {
            kernels::table2()
        },
    };
    let staged = run.staged;
    staged.add(
        out.join("results.json"),
        serde_json::to_string_pretty(&report)?.into_bytes(),
    );
    staged.add(
        out.join("table1.csv"),
        markdown::table1_csv(&report).into_bytes(),
    );
    staged.add(
        out.join("tables.md"),
        markdown::document(&report).into_bytes(),
    );
    staged.publish(&out)?;
    Ok((report, out))
}
