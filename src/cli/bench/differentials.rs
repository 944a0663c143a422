//! `photonmap bench differentials`: photon differentials (Fabianowski and
//! Dingliana 2009) against the kNN-grid on one scene, at the same photons
//! (the kNN map's bounces, and no caustic footprint map):
//!
//! - **Methods**: the kNN-grid at the scene's defaults and photon
//!   differentials at theirs; time by component, error against the SPPM
//!   reference over all pixels and over the indirect pixels (where the
//!   reference exceeds the direct-only image by more than 10% of the
//!   reference's mean: caustics in GLASS BALL and RING, every bounce of
//!   light in CORNELL BOX), and k (the kNN's) or k_PD (footprints at a hit).
//! - **Leaf size** (their Table 1): the estimate's time with leaves of 1 to
//!   512 footprints and with the automatic threshold.
//! - **k_PM ~ k_PD** (their Table 2's claim): footprints scaled by m (both
//!   smoothing factors; k_PD grows as m^2), each beside the kNN-grid with k
//!   set to the k_PD measured.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use serde::Serialize;

use photonmap::gpu::{Gpu, Platform};
use photonmap::metrics::compare;
use photonmap::render::{
    render, DifferentialsOptions, DifferentialsReport, Image, Method, RenderOptions, RenderOutput,
    WithPhotons,
};
use photonmap::scene::Scene;

use super::output::{folder, write_json, write_row_png, BenchOutput};
use super::reference::{reference_options, scaled_size};
use super::scene::{BenchScene, Loaded, SEED};

#[derive(Args)]
pub struct DifferentialsBenchArgs {
    #[command(flatten)]
    pub scene: BenchScene,
    /// Fewer leaf sizes and footprint scales.
    #[arg(long)]
    pub quick: bool,
    /// Folder for each row's PNG (default photonmap-out/differentials/<scene>).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub output: BenchOutput,
}

/// One render.
#[derive(Serialize, Clone, Debug)]
pub struct Row {
    pub label: String,
    pub method: String,
    /// k of the kNN estimate, or k_PD (mean footprints at a first hit).
    pub k: f64,
    pub leaf_size: Option<u32>,
    pub smoothing: Option<f32>,
    pub caustic_smoothing: Option<f32>,
    pub seconds: f64,
    /// Wall seconds: photons (tracing, differentials), map (build, BVH,
    /// smoothing pilot), estimate.
    pub photons: f64,
    pub map: f64,
    pub estimate: f64,
    /// Mean BVH nodes visited and footprints examined at a first hit.
    pub nodes: Option<f64>,
    pub examined: Option<f64>,
    pub rmse: Option<f64>,
    /// Relative MSE: not dominated, as RMSE is at 1 spp, by a bright
    /// emitter's aliased edge against the antialiased reference.
    pub rel_mse: Option<f64>,
    pub ssim: Option<f64>,
    pub indirect_rmse: Option<f64>,
    /// The indirect pixels' mean over the reference's (1: no bias in the sum).
    pub indirect_mean_ratio: Option<f64>,
}

#[derive(Serialize)]
pub struct DifferentialsBench {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub reference: Option<String>,
    pub indirect_pixels: usize,
    pub renderer: String,
    pub methods: Vec<Row>,
    pub leaf_sizes: Vec<Row>,
    pub k_pairs: Vec<Row>,
}

fn component(stage: &str) -> usize {
    match stage {
        "trace photons" | "photon differentials" => 0,
        "build map" | "footprint map" | "smoothing pilot" => 1,
        "radiance estimate" | "footprint estimate" => 2,
        _ => 3,
    }
}

struct Bench<'a> {
    gpu: &'a Gpu,
    scene: &'a Scene,
    scale: u32,
    reference: Option<&'a Image>,
    indirect: Option<Vec<bool>>,
    dir: PathBuf,
    progress: Box<dyn Fn(&str)>,
    rendered: usize,
}

impl Bench<'_> {
    fn options(&self) -> RenderOptions {
        reference_options(self.scene, self.scale, SEED)
    }

    /// The bench's options with photon differentials `d`.
    /// `d` on the kNN map's own photons, as the paper compares them: the
    /// scene's bounces, and no caustic footprint map of photons of its own.
    fn with_differentials(&self, d: DifferentialsOptions) -> RenderOptions {
        let d = DifferentialsOptions {
            caustic_photons: Some(0),
            max_bounces: self.scene.photon_map.max_bounces,
            ..d
        };
        let o = self.options();
        let map = o.method.photon_map().cloned().unwrap_or_default();
        o.with_method(Method::Differentials(WithPhotons::from_map(map, d)))
    }

    fn row(&mut self, label: &str, o: &RenderOptions) -> Result<(Row, RenderOutput)> {
        self.row_on(self.scene, label, o)
    }

    /// A row of `scene` (the bench's, or it with another k).
    fn row_on(
        &mut self,
        scene: &Scene,
        label: &str,
        o: &RenderOptions,
    ) -> Result<(Row, RenderOutput)> {
        (self.progress)(label);
        let r = render(self.gpu, scene, o, &mut ())?;
        let parts: [f64; 4] = r.timings.wall_by_component(component);
        let (rmse, rel_mse, ssim, indirect_rmse, ratio) = match self.reference {
            Some(img) => {
                let m = compare(&r.image, img, None)?;
                let (c, ratio) = match &self.indirect {
                    Some(mask) if mask.iter().any(|&b| b) => {
                        let mean = |i: &Image| -> f64 {
                            i.pixels
                                .iter()
                                .zip(mask)
                                .filter(|(_, &m)| m)
                                .map(|(p, _)| f64::from(p[0] + p[1] + p[2]))
                                .sum()
                        };
                        (
                            Some(compare(&r.image, img, Some(mask))?.rmse),
                            Some(mean(&r.image) / mean(img)),
                        )
                    }
                    _ => (None, None),
                };
                (Some(m.rmse), Some(m.rel_mse), Some(m.ssim), c, ratio)
            }
            None => (None, None, None, None, None),
        };
        write_row_png(&self.dir, self.rendered, label, &r.image)?;
        self.rendered += 1;
        let pd = r.differentials();
        let pd = pd.as_ref();
        let stats = r.footprint_estimates().first();
        let row = Row {
            label: label.into(),
            method: if pd.is_some() {
                "differentials"
            } else {
                "kNN-grid"
            }
            .into(),
            k: stats.map_or(scene.photon_map.k as f64, |s| s.mean_footprints),
            leaf_size: pd.map(|d| d.leaf_size),
            smoothing: pd.map(|d| d.smoothing),
            caustic_smoothing: pd.map(|d| d.caustic_smoothing),
            seconds: r.timings.wall_seconds,
            photons: parts[0],
            map: parts[1],
            estimate: parts[2],
            nodes: stats.map(|s| s.mean_nodes),
            examined: stats.map(|s| s.mean_examined),
            rmse,
            rel_mse,
            ssim,
            indirect_rmse,
            indirect_mean_ratio: ratio,
        };
        Ok((row, r))
    }
}

pub fn run(a: &DifferentialsBenchArgs, platform: Platform) -> Result<()> {
    let Loaded {
        scene,
        name,
        reference,
        scale,
    } = a.scene.load()?;
    let gpu = crate::cli::gpu(platform)?;
    let dir = folder(a.out.as_deref(), "differentials", Some(&name))?;
    let mut bench = Bench {
        gpu: &gpu,
        scene: &scene,
        scale,
        reference: reference.as_ref().map(|(_, i)| i),
        indirect: None,
        dir: dir.clone(),
        progress: Box::new(a.output.progress()),
        rendered: 0,
    };
    // The indirect pixels: the reference above the direct-only image.
    if let Some((_, img)) = &reference {
        let direct = render(&gpu, &scene, &bench.options().direct_only(), &mut ())?;
        let mean = img
            .pixels
            .iter()
            .map(|p| p.iter().sum::<f32>() / 3.0)
            .sum::<f32>()
            / img.pixels.len().max(1) as f32;
        bench.indirect = Some(
            img.pixels
                .iter()
                .zip(&direct.image.pixels)
                .map(|(r, d)| (0..3).map(|c| r[c] - d[c]).sum::<f32>() / 3.0 > 0.1 * mean)
                .collect(),
        );
    }
    let mut methods = Vec::new();
    methods.push(bench.row("kNN-grid", &bench.options())?.0);
    let (pd, out) = bench.row(
        "differentials",
        &bench.with_differentials(DifferentialsOptions::default()),
    )?;
    let auto = out
        .differentials()
        .as_ref()
        .expect("a differentials render reports its map")
        .clone();
    methods.push(pd);

    let leaf_sizes = leaf_rows(&mut bench, &auto, a.quick)?;
    let k_pairs = k_rows(&mut bench, &scene, &auto, a.quick)?;

    let (width, height) = scaled_size(&scene, scale);
    let report = DifferentialsBench {
        scene: name,
        width,
        height,
        reference: reference.as_ref().map(|(p, _)| p.display().to_string()),
        indirect_pixels: bench
            .indirect
            .as_ref()
            .map_or(0, |m| m.iter().filter(|&&b| b).count()),
        renderer: gpu.capabilities().gl_renderer,
        methods,
        leaf_sizes,
        k_pairs,
    };
    write_json(&dir.join("differentials.json"), &report)?;
    a.output.print(&report, |r| {
        print_table(r);
        eprintln!("wrote {}", dir.display());
    })
}

/// Their Table 1: the map at s fixed to the automatic run's, with each leaf
/// size, then the automatic one.
fn leaf_rows(bench: &mut Bench<'_>, auto: &DifferentialsReport, quick: bool) -> Result<Vec<Row>> {
    let sizes: Vec<u32> = if quick {
        vec![4, 16, 64, 256]
    } else {
        (0..10).map(|i| 1 << i).collect()
    };
    let mut leaf_sizes = Vec::new();
    let fixed = DifferentialsOptions {
        smoothing: Some(auto.smoothing),
        ..DifferentialsOptions::default()
    };
    for t in sizes {
        let o = bench.with_differentials(DifferentialsOptions {
            leaf_size: Some(t),
            ..fixed.clone()
        });
        leaf_sizes.push(bench.row(&format!("leaf size {t}"), &o)?.0);
    }
    let o = bench.with_differentials(fixed.clone());
    leaf_sizes.push(
        bench
            .row(&format!("leaf size auto ({})", auto.auto_leaf_size), &o)?
            .0,
    );

    Ok(leaf_sizes)
}

/// k_PM ~ k_PD: footprints scaled by m beside the kNN-grid at the k_PD reached.
fn k_rows(
    bench: &mut Bench<'_>,
    scene: &Scene,
    auto: &DifferentialsReport,
    quick: bool,
) -> Result<Vec<Row>> {
    let scales: &[f32] = if quick {
        &[0.5, 1.0]
    } else {
        &[
            0.5,
            std::f32::consts::FRAC_1_SQRT_2,
            1.0,
            std::f32::consts::SQRT_2,
        ]
    };
    let mut k_pairs = Vec::new();
    for &m in scales {
        let o = bench.with_differentials(DifferentialsOptions {
            smoothing: Some(auto.smoothing * m),
            caustic_smoothing: auto.caustic_smoothing * m,
            ..DifferentialsOptions::default()
        });
        let (row, _) = bench.row(&format!("footprints x {m:.2}"), &o)?;
        let k = (row.k.round() as u32).max(1);
        k_pairs.push(row);
        let mut s = scene.clone();
        s.photon_map.k = k;
        let o = bench.options();
        k_pairs.push(bench.row_on(&s, &format!("kNN-grid, k = {k}"), &o)?.0);
    }

    Ok(k_pairs)
}

fn print_table(r: &DifferentialsBench) {
    println!(
        "{} ({} x {}, {}; {} indirect pixels)",
        r.scene, r.width, r.height, r.renderer, r.indirect_pixels
    );
    println!(
        "{:<26} {:>7} {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} {:>9} {:>9} {:>8} {:>8} {:>7}",
        "run",
        "k",
        "seconds",
        "photons",
        "map",
        "estimate",
        "nodes",
        "examined",
        "RMSE",
        "rel. MSE",
        "SSIM",
        "indirect",
        "i. mean"
    );
    let opt = |v: Option<f64>, p: usize| v.map_or("-".into(), |v| format!("{v:.p$}"));
    for (title, rows) in [
        ("methods", &r.methods),
        ("leaf size (Table 1)", &r.leaf_sizes),
        ("k_PM ~ k_PD", &r.k_pairs),
    ] {
        println!("-- {title}");
        for x in rows {
            println!(
                "{:<26} {:>7.1} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>7} {:>8} {:>9} {:>9} {:>8} {:>8} {:>7}",
                x.label,
                x.k,
                x.seconds,
                x.photons,
                x.map,
                x.estimate,
                opt(x.nodes, 1),
                opt(x.examined, 1),
                opt(x.rmse, 5),
                opt(x.rel_mse, 5),
                opt(x.ssim, 4),
                opt(x.indirect_rmse, 5),
                opt(x.indirect_mean_ratio, 3),
            );
        }
    }
}
