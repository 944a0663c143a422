//! What `bench mitsuba` reports (mitsuba.json): a row per render and the
//! convergence curves; and its table (stdout and table.md) and convergence
//! plot.

use std::path::Path;

use anyhow::Result;
use serde::Serialize;

use photonmap::bench::regions::RegionEnergy;
use photonmap::image::write_atomically;

use crate::cli::bench::output::{command_line, write_json};
use crate::cli::bench::plot::LogLog;

#[derive(Serialize, Clone, Debug)]
pub struct Row {
    pub renderer: String,
    /// The wall time it was given: a --seconds budget, or the one-map
    /// render's time with --spp (None for that render itself).
    pub budget: Option<f64>,
    /// Wall seconds it took (Mitsuba: its first render call on, JIT
    /// included; SPPM and VCM: setup included).
    pub seconds: f64,
    /// Samples per pixel (Mitsuba, the one-map render) or iterations (SPPM,
    /// VCM: one camera path a pixel each).
    pub samples: u32,
    /// Camera paths a second: samples x width x height / seconds.
    pub paths_per_second: f64,
    /// SPPM: photons emitted a second; VCM: light paths traced a second.
    pub photons_per_second: Option<f64>,
    /// RMSE over the reference's mean, on the mask's pixels: the headline.
    pub rel_rmse: f64,
    /// The image's mean over the reference's, same pixels.
    pub energy: f64,
    /// Mean of (a - b)^2 / (b^2 + 0.01).
    pub rel_mse: f64,
    pub rmse: f64,
    /// The image's energy in each `--region`, against the reference's.
    pub regions: Vec<RegionEnergy>,
    /// PNG in the out folder (the EXR beside it has the same stem).
    pub image: String,
}

/// One image along a method's longest run.
#[derive(Serialize, Clone, Debug)]
pub struct CurvePoint {
    pub seconds: f64,
    pub samples: u32,
    pub rel_rmse: f64,
    pub energy: f64,
    pub rel_mse: f64,
    pub image: String,
}

/// Error against wall time for one method, along its longest run.
#[derive(Serialize, Clone, Debug)]
pub struct Curve {
    pub renderer: String,
    pub points: Vec<CurvePoint>,
}

#[derive(Serialize)]
pub struct MitsubaBench {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference: String,
    /// "truth" (the committed ground truth), "given" (--reference) or "SPPM
    /// reference".
    pub reference_kind: String,
    pub mask: Option<String>,
    pub pixels_compared: usize,
    /// The reference's own relative noise: the truth's noise.json figure
    /// (full-size image), or a --mitsuba-reference's from its two runs.
    /// Nothing is measured more finely.
    pub truth_noise: Option<f64>,
    pub gl_renderer: String,
    pub variant: String,
    pub max_depth: i32,
    pub budgets: Vec<f64>,
    pub rows: Vec<Row>,
    pub curves: Vec<Curve>,
    pub convergence_plot: String,
}

pub(super) const PLOT_FILE: &str = "convergence.svg";
const TABLE_FILE: &str = "table.md";
const REGIONS_FILE: &str = "regions.md";

/// The report's files beside the images: the convergence plot, mitsuba.json
/// and the table.
pub(super) fn write(dir: &Path, report: &MitsubaBench) -> Result<()> {
    let svg = plot(report);
    write_atomically(&dir.join(PLOT_FILE), svg.as_bytes())?;
    write_json(&dir.join("mitsuba.json"), report)?;
    let table = markdown_table(report, &command_line());
    write_atomically(&dir.join(TABLE_FILE), table.as_bytes())?;
    if let Some(regions) = regions_table(report, &command_line()) {
        write_atomically(&dir.join(REGIONS_FILE), regions.as_bytes())?;
    }
    Ok(())
}

/// The rows as a Markdown table, headed by the command that made them, for
/// the documentation to link rather than retype.
fn markdown_table(b: &MitsubaBench, command: &str) -> String {
    let mut s = format!("`{command}`\n\n{}; {}.\n\n", heading(b), b.gl_renderer);
    s += "| renderer | budget (s) | seconds | samples | camera paths/s | photons/s | relative RMSE | energy |\n";
    s += "|---|---|---|---|---|---|---|---|\n";
    for r in &b.rows {
        s += &format!(
            "| {} | {} | {:.1} | {} | {:.3e} | {} | {:.4} | {:.4} |\n",
            r.renderer,
            budget(r, 0),
            r.seconds,
            r.samples,
            r.paths_per_second,
            photons_per_second(r),
            r.rel_rmse,
            r.energy
        );
    }
    s
}

/// Each row's energy in each `--region` (none without them), headed by the
/// command.
fn regions_table(b: &MitsubaBench, command: &str) -> Option<String> {
    let first = b.rows.first().filter(|r| !r.regions.is_empty())?;
    let mut s = format!(
        "`{command}`\n\n{}; {}. Each region's energy: the image's mean there over the reference's.\n\n",
        heading(b),
        b.gl_renderer
    );
    s += "| renderer | budget (s) |";
    for r in &first.regions {
        s += &format!(" {} ({} px) |", r.name, r.pixels);
    }
    s += &format!("\n|---|---|{}\n", "---|".repeat(first.regions.len()));
    for row in &b.rows {
        s += &format!("| {} | {} |", row.renderer, budget(row, 0));
        for r in &row.regions {
            s += &format!(" {:.3} |", r.energy);
        }
        s += "\n";
    }
    Some(s)
}

/// A row's budget with `decimals` decimals, or "-" for the one-map render.
fn budget(r: &Row, decimals: usize) -> String {
    r.budget.map_or("-".into(), |x| format!("{x:.decimals$}"))
}

/// A row's photons a second, or "-" for renderers that emit none.
fn photons_per_second(r: &Row) -> String {
    r.photons_per_second
        .map_or("-".into(), |p| format!("{p:.3e}"))
}

const COLOURS: [&str; 6] = [
    "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#8c564b", "#9467bd",
];

/// Relative RMSE against seconds: each method's longest run joined, its
/// shorter budgets as dots, the one-map renders as labelled dots, and the
/// truth's own noise as a level.
fn plot(b: &MitsubaBench) -> String {
    let (name, rows, curves) = (&b.scene, &b.rows, &b.curves);
    let mask = if b.mask.is_some() {
        "interior mask"
    } else {
        "all pixels"
    };
    let mut p = LogLog::new(
        &format!(
            "{name}: error against wall time ({}, {mask})",
            b.reference_kind
        ),
        "wall seconds",
        "relative RMSE (RMSE / mean of the reference)",
    );
    for (c, colour) in curves.iter().zip(COLOURS.iter().cycle()) {
        p.line(
            &c.renderer,
            colour,
            c.points.iter().map(|q| (q.seconds, q.rel_rmse)).collect(),
        );
        let on_curve = |r: &Row| c.points.iter().any(|q| q.image == r.image);
        let others: Vec<_> = rows
            .iter()
            .filter(|r| r.renderer == c.renderer && !on_curve(r))
            .map(|r| (r.seconds, r.rel_rmse, String::new()))
            .collect();
        p.points(colour, others, false);
    }
    let one_map: Vec<_> = rows
        .iter()
        .filter(|r| r.budget.is_none())
        .map(|r| {
            (
                r.seconds,
                r.rel_rmse,
                format!("photonmap {} spp", r.samples),
            )
        })
        .collect();
    if !one_map.is_empty() {
        p.points("#9467bd", one_map, false);
    }
    if let Some(n) = b.truth_noise {
        p.level("the reference's own noise", "#7f7f7f", n);
    }
    p.svg()
}

/// What was compared with what: the tables' first line.
fn heading(b: &MitsubaBench) -> String {
    format!(
        "{} ({} x {}), against {} ({}), {}, {} pixels{}",
        b.scene,
        b.width,
        b.height,
        b.reference,
        b.reference_kind,
        b.mask
            .as_deref()
            .map_or("no mask".into(), |m| format!("mask {m}")),
        b.pixels_compared,
        b.truth_noise.map_or(String::new(), |n| format!(
            ", whose own noise is {:.2}%",
            100.0 * n
        ))
    )
}

pub(super) fn print_table(b: &MitsubaBench) {
    println!("{}", heading(b));
    println!(
        "{:<16} {:>7} {:>8} {:>8} {:>9} {:>9} {:>9} {:>7} {:>8}  image",
        "renderer",
        "budget",
        "seconds",
        "samples",
        "paths/s",
        "photons/s",
        "rel.RMSE",
        "energy",
        "rel.MSE"
    );
    for r in &b.rows {
        println!(
            "{:<16} {:>7} {:>8.2} {:>8} {:>9.3e} {:>9} {:>9.4} {:>7.4} {:>8.4}  {}",
            r.renderer,
            budget(r, 1),
            r.seconds,
            r.samples,
            r.paths_per_second,
            photons_per_second(r),
            r.rel_rmse,
            r.energy,
            r.rel_mse,
            r.image
        );
    }
    for c in &b.curves {
        let points: Vec<String> = c
            .points
            .iter()
            .map(|q| format!("{:.1} s {:.4}", q.seconds, q.rel_rmse))
            .collect();
        println!("curve {:<16} {}", c.renderer, points.join(", "));
    }
}
