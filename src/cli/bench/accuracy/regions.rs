//! `bench accuracy --regions`: each run's energy and error on every diffuse
//! surface the pixels see first (from the ray tracer's first-hit record) and
//! on rectangles named with `--region`, as a table, `regions.csv`, `regions.md` and the
//! runs' JSON.

use anyhow::{bail, Result};
use clap::Args;

use photonmap::bench::regions::{first_hit_regions, Rectangle, Region};
use photonmap::gpu::Gpu;
use photonmap::metrics::compare;
use photonmap::render::Image;
use photonmap::scene::Scene;

use super::report::{AccuracyReport, RegionScore, RegionSize};

#[derive(Args, Debug, Clone, Default)]
pub struct RegionArgs {
    /// Report every run's energy and error on each diffuse surface the
    /// pixels see first, and write every run's bias map (bias/<run>.png)
    /// and regions.csv and regions.md (a table a row a run).
    #[arg(long)]
    pub regions: bool,
    /// A rectangle to report as a region too (implies --regions):
    /// NAME=X0:X1:Y0:Y1, columns X0..X1 and rows Y0..Y1 of the reference's
    /// pixels, row 0 at the top, ends excluded. Repeat it for more.
    #[arg(long, value_name = "NAME=X0:X1:Y0:Y1")]
    pub region: Vec<String>,
}

impl RegionArgs {
    pub fn wanted(&self) -> bool {
        self.regions || !self.region.is_empty()
    }

    /// Refuses a malformed `--region` before anything renders.
    pub fn check(&self) -> Result<()> {
        self.rectangles().map(|_| ())
    }

    fn rectangles(&self) -> Result<Vec<Rectangle>> {
        self.region
            .iter()
            .map(|r| {
                r.parse()
                    .map_err(|e: String| anyhow::anyhow!("--region {e}"))
            })
            .collect()
    }
}

/// The regions in use, each cut to the compared pixels.
#[derive(Default)]
pub struct Regions {
    list: Vec<Region>,
}

impl Regions {
    /// The surfaces seen first at the reference's size, then the rectangles,
    /// each within `mask`; regions left empty are dropped.
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        reference: &Image,
        mask: Option<&[bool]>,
        args: &RegionArgs,
    ) -> Result<Self> {
        let (w, h) = (reference.width, reference.height);
        let mut list = first_hit_regions(gpu, scene, w, h)?;
        for r in args.rectangles()? {
            if r.x1 > w || r.y1 > h {
                bail!(
                    "--region {}={}:{}:{}:{}: outside the reference's {w} x {h} pixels",
                    r.name,
                    r.x0,
                    r.x1,
                    r.y0,
                    r.y1
                );
            }
            list.push(r.region(w, h));
        }
        for r in &mut list {
            if let Some(m) = mask {
                r.pixels.iter_mut().zip(m).for_each(|(p, &k)| *p &= k);
            }
        }
        list.retain(|r| r.count() > 0);
        Ok(Self { list })
    }

    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    pub fn sizes(&self) -> Vec<RegionSize> {
        self.list
            .iter()
            .map(|r| RegionSize {
                name: r.name.clone(),
                pixels: r.count(),
            })
            .collect()
    }

    /// Each region's energy (the seeds' mean, with the spread of one seed's)
    /// and one render's relative RMSE.
    pub fn score(
        &self,
        images: &[Image],
        mean: &Image,
        reference: &Image,
    ) -> Result<Vec<RegionScore>> {
        let n = images.len() as f64;
        self.list
            .iter()
            .map(|r| {
                let one = images
                    .iter()
                    .map(|img| compare(img, reference, Some(&r.pixels)))
                    .collect::<Result<Vec<_>, _>>()?;
                let energies: Vec<f64> = one.iter().map(|m| m.energy).collect();
                let e = energies.iter().sum::<f64>() / n;
                let var =
                    energies.iter().map(|x| (x - e) * (x - e)).sum::<f64>() / (n - 1.0).max(1.0);
                Ok(RegionScore {
                    name: r.name.clone(),
                    energy: compare(mean, reference, Some(&r.pixels))?.energy,
                    energy_noise: (var / n).sqrt(),
                    rel_rmse: one.iter().map(|m| m.rel_rmse).sum::<f64>() / n,
                })
            })
            .collect()
    }
}

/// A file name for a run's label: lower case, runs of other characters as "-".
pub fn slug(label: &str) -> String {
    let mut out = String::new();
    for c in label.chars() {
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_matches('-').to_string()
}

/// `regions.csv`: a row a run and region.
pub fn csv(report: &AccuracyReport) -> String {
    let mut s = String::from("label,method,region,pixels,energy,energy_noise,rel_rmse,seconds\n");
    let quote = super::plot::csv_quoted;
    for run in &report.runs {
        for (score, size) in run.regions.iter().zip(&report.regions) {
            s += &format!(
                "{},{},{},{},{:.4},{:.4},{:.4},{:.3}\n",
                quote(&run.label),
                run.method.name(),
                quote(&score.name),
                size.pixels,
                score.energy,
                score.energy_noise,
                score.rel_rmse,
                run.seconds
            );
        }
    }
    s
}

/// `regions.md`: the command, then a Markdown table, a row a run and a
/// column a region, of energy (image over reference) with its standard
/// error from the seeds.
pub fn markdown(report: &AccuracyReport) -> String {
    let mut s = format!(
        "`{}`\n\n{} seeds a run; {}.\n\n| run | seconds | rel RMSE | energy |",
        report.command, report.seeds, report.renderer
    );
    let mut rule = String::from("|---|---|---|---|");
    for r in &report.regions {
        s += &format!(" {} ({} px) |", r.name, r.pixels);
        rule += "---|";
    }
    s += &format!("\n{rule}\n");
    for run in &report.runs {
        s += &format!(
            "| {} | {:.2} | {:.3} | {:.3} |",
            run.label, run.seconds, run.rel_rmse, run.energy
        );
        for score in &run.regions {
            s += &format!(" {:.3} ± {:.3} |", score.energy, score.energy_noise);
        }
        s.push('\n');
    }
    s
}

/// Every run's energy by region, a column a region (numbered; the names below).
pub fn print_table(report: &AccuracyReport) {
    if report.regions.is_empty() {
        return;
    }
    println!();
    println!("energy by region (image over reference; regions below)");
    print!(
        "{:<34} {:>8} {:>7} {:>7}",
        "run", "seconds", "relRMSE", "energy"
    );
    for i in 0..report.regions.len() {
        print!(" {:>6}", format!("R{}", i + 1));
    }
    println!();
    for run in &report.runs {
        print!(
            "{:<34} {:>8.3} {:>7.3} {:>7.3}",
            run.label, run.seconds, run.rel_rmse, run.energy
        );
        for score in &run.regions {
            print!(" {:>6.3}", score.energy);
        }
        println!();
    }
    for (i, r) in report.regions.iter().enumerate() {
        println!("R{}: {} ({} pixels)", i + 1, r.name, r.pixels);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slugs_are_file_names() {
        assert_eq!(
            slug("IGI 256 paths, all three, 4 spp"),
            "igi-256-paths-all-three-4-spp"
        );
        assert_eq!(slug("scene defaults"), "scene-defaults");
    }
}
