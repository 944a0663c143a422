//! `tables`' report as Markdown (tables.md, and stdout without --json) and
//! Table 1 as CSV.

use super::report::{TablesReport, FIGURE8_BUDGET, STAGES};

pub(super) fn table1_csv(r: &TablesReport) -> String {
    let mut s = String::from(
        "scene,build,stage,median_wall_s,min_wall_s,max_wall_s,median_gpu_s,paper_s,ratio\n",
    );
    for c in &r.table1 {
        s += &format!(
            "{},{:?},{},{:.4},{:.4},{:.4},{:.4},{},{:.4}\n",
            c.scene,
            c.build,
            c.stage,
            c.median_wall_seconds,
            c.min_wall_seconds,
            c.max_wall_seconds,
            c.median_gpu_seconds,
            c.paper_seconds,
            c.ratio_to_paper
        );
    }
    s
}

/// The whole report, tables.md: Table 1, section 3.3, the pass counts,
/// figures 7 and 8 and Table 2, each beside the paper's figures.
pub(super) fn document(r: &TablesReport) -> String {
    let mut s = format!(
        "# The paper's tables on {}\n\n`{}`: {} ({} cores), {}, {} run{} a cell (median; min..max).\nPaper figures: GeForce FX 5900 Ultra (2003), in brackets. Times are wall clock with glFinish at each stage's ends.\n\n",
        r.renderer,
        r.command,
        r.gl_version,
        r.cores,
        r.image_scale,
        r.runs,
        if r.runs == 1 { "" } else { "s" }
    );
    s += "## Table 1: seconds per stage\n\n| scene | build | trace photons | build map | trace rays | radiance estimate | total | total / paper |\n|---|---|---|---|---|---|---|---|\n";
    for t in &r.totals {
        let cells: Vec<String> = STAGES
            .iter()
            .map(|st| {
                let c = r
                    .table1
                    .iter()
                    .find(|c| c.scene == t.scene && c.build == t.build && c.stage == *st)
                    .expect("cell");
                let mark = if c.at_or_below_paper { "" } else { " ▲" };
                format!(
                    "{:.2} ({}){mark} <br>{:.2}..{:.2}",
                    c.median_wall_seconds, c.paper_seconds, c.min_wall_seconds, c.max_wall_seconds
                )
            })
            .collect();
        s += &format!(
            "| {} | {:?} | {} | {:.2} ({:.1}) | {:.2}{} |\n",
            t.scene,
            t.build,
            cells.join(" | "),
            t.median_seconds,
            t.paper_seconds,
            t.ratio_to_paper,
            if t.at_most_a_quarter { "" } else { " ▲" }
        );
    }
    s +=
        "\n▲ marks a cell above the paper's figure, or a total above a quarter of the paper's.\n\n";
    s += &format!(
        "Stencil routing: m = {}{}.\n\n",
        r.stencil_m,
        if r.faithful {
            "; the paper's 2003 constraints (--faithful): a random-number texture, read-back before routing, float addressing, no compaction, the faithful sort passes, no projection maps"
        } else {
            ""
        }
    );
    if r.table1_only {
        s += "## Figure 7: bitonic, stencil routing, software (kd-tree), per scene\n\n![figure 7](figure7.png)\n";
        return s;
    }
    s += "## Section 3.3: full convergence of the radiance estimate by drawing mode (seconds)\n\nPaper: CORNELL BOX 104 s full screen, 52.4 s with 16 x 16 tiles; GLASS BALL 102 s and 14.9 s.\n\n| scene | mode | seconds | passes | tile draws |\n|---|---|---|---|---|\n";
    for c in &r.convergence {
        s += &format!(
            "| {} | {} | {:.2} | {} | {} |\n",
            c.scene, c.mode, c.wall_seconds, c.passes, c.tile_draws
        );
    }
    s += "\n## Bitonic passes against n (paper: 210 passes for 1024 x 1024)\n\n| photons | passes | sort ms | ms a pass | copy pass ms | pass / copy | binary search ms | stencil routing ms | with read-back ms |\n|---|---|---|---|---|---|---|---|---|\n";
    for p in &r.passes {
        s += &format!(
            "| {} | {} | {:.2} | {:.3} | {:.3} | {:.2} | {:.3} | {:.2} | {:.2} |\n",
            p.photons,
            p.bitonic_passes,
            p.bitonic_sort_seconds * 1e3,
            p.bitonic_seconds_per_pass * 1e3,
            p.copy_pass_seconds * 1e3,
            p.pass_to_copy_ratio,
            p.binary_search_seconds * 1e3,
            p.stencil_vertex_fetch_seconds * 1e3,
            p.stencil_readback_seconds * 1e3
        );
    }
    s += "\n## Figure 7: bitonic, stencil routing, software (kd-tree), per scene\n\n![figure 7](figure7.png)\n\n";
    let Some(figure8) = &r.figure8 else {
        return s;
    };
    s += &format!(
        "## Figure 8: the GLASS BALL caustic during convergence\n\n![figure 8](figure8.png)\n\nDrawn {} steps a pass. Snapshots at {} s (the last is the final image). Full convergence {:.2} s; visually converged at {:.2} s ({}). Paper: about 4 s of 14.9 s.\n\n",
        FIGURE8_BUDGET,
        figure8.snapshots.iter().map(|s| format!("{:.2}", s.1)).collect::<Vec<_>>().join(", "),
        figure8.full_convergence_seconds,
        figure8.visual_convergence_seconds,
        figure8.criterion
    );
    s += "## Table 2 analogue: instructions per kernel\n\nStatic counts of the whole kernel (a loop body once) in SPIR-V from `glslangValidator -G -Os`, not the driver's own code; *Addr* counts integer and conversion operations; *Pack* is 0 because every output has its own render target. The paper's Cg counts (one iteration) in brackets.\n\n";
    match &r.table2 {
        Ok(rows) => {
            s += "| kernel | instructions | texture fetches | address arithmetic | packing |\n|---|---|---|---|---|\n";
            for k in rows {
                s += &format!(
                    "| {} | {} ({}) | {} ({}) | {} ({}) | {} ({}) |\n",
                    k.kernel,
                    k.instructions,
                    k.paper[0],
                    k.texture_fetches,
                    k.paper[1],
                    k.address_arithmetic,
                    k.paper[2],
                    k.packing,
                    k.paper[3]
                );
            }
        }
        Err(e) => s += &format!("Not measured: {e}.\n"),
    }
    s
}
