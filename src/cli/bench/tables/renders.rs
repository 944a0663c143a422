//! The renders behind `tables`: Table 1 (every stage of each paper scene
//! and build over the runs, and figure 7's images from the first run),
//! section 3.3 (the estimate's full convergence by drawing mode) and figure
//! 8 (the GLASS BALL caustic during convergence), and the image handling
//! they need.

use std::path::Path;

use anyhow::{Context, Result};

use photonmap::gpu::Gpu;
use photonmap::photon::{BuildMethod, PhotonConfig};
use photonmap::render::software::software_image;
use photonmap::render::{
    render, EstimateMode, Image, Method, PhotonMapOptions, RenderOptions, StageTiming, Timings,
};
use photonmap::scene::{embedded, Scene};

use super::report::{ConvergenceRow, Figure8, Table1Cell, Table1Total, FIGURE8_BUDGET, STAGES};
use super::staged::Staged;
use crate::cli::bench::reference::scaled_size;
use crate::cli::render::{SnapshotEvery, SnapshotWriter};

/// Table 1 of the paper (GeForce FX 5900 Ultra, seconds).
const PAPER_TABLE1: [(&str, [f64; 4], [f64; 4]); 3] = [
    ("glass_ball", [1.2, 0.8, 0.5, 14.9], [1.2, 1.8, 0.5, 7.8]),
    ("ring", [1.3, 0.8, 0.4, 6.5], [1.3, 1.8, 0.4, 4.6]),
    ("cornell_box", [2.1, 1.4, 8.4, 52.4], [2.1, 1.7, 8.4, 35.0]),
];

/// One `tables` run: its scale, runs per cell and output folder.
pub(super) struct TablesRun<'a> {
    pub(super) gpu: &'a Gpu,
    pub(super) scale: u32,
    pub(super) runs: u32,
    pub(super) quick: bool,
    pub(super) faithful: bool,
    pub(super) stencil_m: u32,
    pub(super) out: &'a Path,
    pub(super) progress: &'a dyn Fn(&str),
    pub(super) staged: Staged,
}

pub(super) type Table1 = (Vec<Table1Cell>, Vec<Table1Total>, Vec<Vec<Image>>);

/// A render at Table 1's settings: 1/`scale` of the paper's resolution,
/// the paper's estimate (no leak test), `build` and `mode`.
pub(crate) fn table1_options(
    scene: &Scene,
    scale: u32,
    build: BuildMethod,
    (faithful, stencil_m): (bool, u32),
    mode: EstimateMode,
) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    (o.width, o.height) = scaled_size(scene, scale);
    o.pass_per_bounce = faithful;
    let mut gi = PhotonMapOptions {
        photons: PhotonConfig {
            build,
            faithful,
            stencil_block: stencil_m,
            // The paper aims no photons: it emits them all from the light.
            projection_maps: !faithful,
            ..PhotonConfig::default()
        },
        ..PhotonMapOptions::default()
    };
    gi.estimate.mode = mode;
    // The paper's estimate, every photon in the sphere, so the times compare
    // with the paper's (the default leak test costs RING about half again).
    gi.estimate.leak = photonmap::render::radiance_estimate::LeakTest::None;
    o.with_method(Method::PhotonMap(gi))
}

/// The median (the mean of the middle two of an even count; 0 of none).
fn median(v: &[f64]) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    if s.is_empty() {
        0.0
    } else if s.len() % 2 == 1 {
        s[s.len() / 2]
    } else {
        0.5 * (s[s.len() / 2 - 1] + s[s.len() / 2])
    }
}

impl TablesRun<'_> {
    fn table1_options(
        &self,
        scene: &Scene,
        build: BuildMethod,
        mode: EstimateMode,
    ) -> RenderOptions {
        table1_options(
            scene,
            self.scale,
            build,
            (self.faithful, self.stencil_m),
            mode,
        )
    }

    /// Table 1 (and figure 7's images from the first run of each).
    pub(super) fn table1(&self) -> Result<Table1> {
        let (mut table1, mut totals, mut figure7_rows) = (Vec::new(), Vec::new(), Vec::new());
        for (name, paper_bitonic, paper_stencil) in PAPER_TABLE1 {
            let scene = embedded::load(name)?;
            let mut row = Vec::new();
            for (build, paper) in [
                (BuildMethod::Bitonic, paper_bitonic),
                (BuildMethod::Stencil, paper_stencil),
            ] {
                let (cells, total) = self.table1_cell(name, &scene, build, paper, &mut row)?;
                table1.extend(cells);
                totals.push(total);
            }
            // Row order as in figure 7: bitonic, stencil, software.
            row.swap(1, 2);
            figure7_rows.push(row);
        }
        Ok((table1, totals, figure7_rows))
    }

    /// One scene and build of Table 1: every stage over the runs, and the total.
    fn table1_cell(
        &self,
        name: &str,
        scene: &Scene,
        build: BuildMethod,
        paper: [f64; 4],
        row: &mut Vec<Image>,
    ) -> Result<(Vec<Table1Cell>, Table1Total)> {
        let runs = self.runs;
        let mut walls = vec![Vec::new(); 4];
        let mut gpus = vec![Vec::new(); 4];
        let mut run_totals = Vec::new();
        for run in 0..runs {
            (self.progress)(&format!("Table 1: {name} {build:?} run {}/{runs}", run + 1));
            let opts = self.table1_options(scene, build, EstimateMode::Tiled { tile: 16 });
            let r = render(self.gpu, scene, &opts, &mut ())?;
            let mut total = 0.0;
            for (i, stage) in STAGES.iter().enumerate() {
                let (w, g) = stage_seconds(&r.timings, stage);
                walls[i].push(w);
                gpus[i].push(g);
                total += w;
            }
            run_totals.push(total);
            if run == 0 {
                let file = self
                    .out
                    .join("figure7")
                    .join(format!("{name}_{build:?}.png").to_lowercase());
                self.staged.png(file, &r.image)?;
                row.push(r.image.clone());
                if build == BuildMethod::Bitonic {
                    (self.progress)(&format!("Figure 7: {name} software reference"));
                    let sw = software_image(&r, scene).context("software reference")?;
                    let file = self
                        .out
                        .join("figure7")
                        .join(format!("{name}_software.png"));
                    self.staged.png(file, &sw)?;
                    row.push(sw);
                }
            }
        }
        let cells = STAGES
            .iter()
            .enumerate()
            .map(|(i, stage)| {
                let med = median(&walls[i]);
                Table1Cell {
                    scene: scene.name.clone(),
                    build,
                    stage: stage.to_string(),
                    median_wall_seconds: med,
                    min_wall_seconds: walls[i].iter().copied().fold(f64::INFINITY, f64::min),
                    max_wall_seconds: walls[i].iter().copied().fold(0.0, f64::max),
                    median_gpu_seconds: median(&gpus[i]),
                    wall_seconds: walls[i].clone(),
                    paper_seconds: paper[i],
                    ratio_to_paper: med / paper[i],
                    at_or_below_paper: med <= paper[i],
                }
            })
            .collect();
        let paper_total: f64 = paper.iter().sum();
        let med = median(&run_totals);
        let total = Table1Total {
            scene: scene.name.clone(),
            build,
            median_seconds: med,
            paper_seconds: paper_total,
            ratio_to_paper: med / paper_total,
            at_most_a_quarter: med <= paper_total / 4.0,
        };
        Ok((cells, total))
    }

    /// Section 3.3: full convergence of the estimate by drawing mode.
    pub(super) fn section_3_3(&self) -> Result<Vec<ConvergenceRow>> {
        let mut convergence = Vec::new();
        let mut modes: Vec<(String, EstimateMode)> =
            vec![("full screen".into(), EstimateMode::FullScreen)];
        let tiles: &[u32] = if self.quick { &[16] } else { &[8, 16, 32, 64] };
        for &t in tiles {
            modes.push((format!("{t} x {t} tiles"), EstimateMode::Tiled { tile: t }));
        }
        modes.push(("mask every pass".into(), EstimateMode::Masked { every: 1 }));
        for name in ["glass_ball", "cornell_box"] {
            let scene = embedded::load(name)?;
            for (label, mode) in &modes {
                (self.progress)(&format!("Section 3.3: {name} {label}"));
                let opts = self.table1_options(&scene, BuildMethod::Bitonic, *mode);
                let r = render(self.gpu, &scene, &opts, &mut ())?;
                let e = r.estimate().cloned().unwrap_or_default();
                convergence.push(ConvergenceRow {
                    scene: scene.name.clone(),
                    mode: label.clone(),
                    wall_seconds: stage_seconds(&r.timings, "radiance estimate").0,
                    passes: e.passes,
                    tile_draws: e.tile_draws,
                });
            }
        }
        Ok(convergence)
    }

    /// Figure 8: the GLASS BALL caustic during convergence.
    pub(super) fn figure8(&self) -> Result<Figure8> {
        (self.progress)("Figure 8: GLASS BALL snapshots");
        // Snapshots are written to a temporary folder and staged from there.
        let temporary = tempfile::tempdir()?;
        let snap_dir = temporary.path().to_path_buf();
        let scene = embedded::load("glass_ball")?;
        let mut opts = self.table1_options(
            &scene,
            BuildMethod::Bitonic,
            EstimateMode::Tiled { tile: 16 },
        );
        // Finer passes than the default's, so that the snapshots show the
        // estimate converging rather than four or five jumps (the same image).
        if let Some(gi) = opts.photon_map_mut() {
            gi.estimate.budget = FIGURE8_BUDGET;
        }
        let mut writer = SnapshotWriter::new(snap_dir.clone(), SnapshotEvery::Passes(1));
        render(self.gpu, &scene, &opts, &mut writer)?;
        let written = writer.written;
        let final_img = read_png(&snap_dir.join(&written.last().context("no snapshots")?.file))?;
        let mut snaps = Vec::new();
        for s in &written {
            let img = read_png(&snap_dir.join(&s.file))?;
            snaps.push((
                s.file.clone(),
                s.seconds,
                visibly_different(&img, &final_img),
            ));
        }
        let full = written.last().map_or(0.0, |s| s.seconds);
        // Visually converged: from here on, under 1% of pixels visibly differ from the final image.
        let mut visual = full;
        for i in (0..snaps.len()).rev() {
            if snaps[i].2 < 0.01 {
                visual = snaps[i].1;
            } else {
                break;
            }
        }
        let picks: Vec<usize> = [0.1, 0.25, 0.5]
            .iter()
            .map(|f| snaps.iter().position(|s| s.1 >= f * full).unwrap_or(0))
            .chain([snaps.len() - 1])
            .collect();
        let (w, h) = (final_img.width, final_img.height);
        let crops: Vec<Image> = picks
            .iter()
            .map(|&i| {
                read_png(&snap_dir.join(&snaps[i].0)).map(|im| {
                    // Back to linear so png_bytes' sRGB encoding reproduces the snapshot values.
                    let mut c = crop(&im, w * 3 / 10, h / 2, w * 2 / 5, h * 7 / 20);
                    for p in &mut c.pixels {
                        for v in p.iter_mut() {
                            *v = srgb_to_linear(*v);
                        }
                    }
                    c
                })
            })
            .collect::<Result<_>>()?;
        let index = std::iter::once("snapshots.json".to_string());
        for file in written.iter().map(|s| s.file.clone()).chain(index) {
            let bytes = std::fs::read(snap_dir.join(&file))?;
            self.staged.add(self.out.join("figure8").join(&file), bytes);
        }
        self.staged
            .png(self.out.join("figure8.png"), &montage(&[crops]))?;
        Ok(Figure8 {
            file: "figure8.png".into(),
            snapshots: picks.iter().map(|&i| snaps[i].clone()).collect(),
            full_convergence_seconds: full,
            visual_convergence_seconds: visual,
            criterion: "every later snapshot has under 1% of pixels differing from the final image by more than 2 of 255 sRGB levels".into(),
        })
    }
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.04045 {
        v / 12.92
    } else {
        ((v + 0.055) / 1.055).powf(2.4)
    }
}

fn stage_seconds(t: &Timings, stage: &str) -> (f64, f64) {
    let names: &[&str] = match stage {
        "trace rays" => &[
            "eye rays",
            "intersect",
            "shadow rays",
            "specular",
            "eye paths (fused)",
        ],
        other => std::slice::from_ref(match other {
            "trace photons" => &"trace photons",
            "build map" => &"build map",
            _ => &"radiance estimate",
        }),
    };
    let pick = |f: fn(&StageTiming) -> f64| {
        t.stages
            .iter()
            .filter(|s| names.contains(&s.name.as_str()))
            .map(f)
            .sum::<f64>()
    };
    (pick(|s| s.wall_seconds), pick(|s| s.gpu_seconds))
}

/// Places images side by side in rows (all of one row the same height).
pub(super) fn montage(rows: &[Vec<Image>]) -> Image {
    let width = rows
        .iter()
        .map(|r| r.iter().map(|i| i.width).sum::<u32>())
        .max()
        .unwrap_or(1);
    let height = rows
        .iter()
        .map(|r| r.iter().map(|i| i.height).max().unwrap_or(0))
        .sum::<u32>();
    let mut out = Image::new(width, height.max(1));
    let mut y0 = 0;
    for row in rows {
        let mut x0 = 0;
        for img in row {
            for y in 0..img.height {
                for x in 0..img.width {
                    out.pixels[((y0 + y) * width + x0 + x) as usize] = img.get(x, y);
                }
            }
            x0 += img.width;
        }
        y0 += row.iter().map(|i| i.height).max().unwrap_or(0);
    }
    out
}

fn crop(img: &Image, x0: u32, y0: u32, w: u32, h: u32) -> Image {
    let mut out = Image::new(w, h);
    for y in 0..h {
        for x in 0..w {
            out.pixels[(y * w + x) as usize] = img.get(x0 + x, y0 + y);
        }
    }
    out
}

fn read_png(path: &Path) -> Result<Image> {
    let img = image::open(path)
        .with_context(|| format!("reading {}", path.display()))?
        .to_rgb8();
    let (w, h) = img.dimensions();
    // Kept as 8-bit sRGB values over 255: only compared with other PNGs.
    let pixels = img
        .pixels()
        .map(|p| {
            [
                p[0] as f32 / 255.0,
                p[1] as f32 / 255.0,
                p[2] as f32 / 255.0,
            ]
        })
        .collect();
    Ok(Image {
        width: w,
        height: h,
        pixels,
    })
}

/// Fraction of pixels whose 8-bit sRGB value differs from the final image's by
/// more than 2 levels in any channel.
fn visibly_different(a: &Image, b: &Image) -> f64 {
    let n = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .filter(|(p, q)| (0..3).any(|c| (p[c] - q[c]).abs() > 2.5 / 255.0))
        .count();
    n as f64 / a.pixels.len().max(1) as f64
}
