//! What every render writes and prints: provenance, images (all or none),
//! the software reference, the JSON report and `--explain`.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};

use photonmap::image::{write_all_atomically, write_atomically};
use photonmap::provenance::Provenance;
use photonmap::render::{self, Image, RenderOptions};
use photonmap::scene::Scene;

use super::args::Format;

/// What `--json` prints: provenance, the outputs and the run's figures.
#[derive(serde::Serialize)]
pub(super) struct Report<'a> {
    pub(super) provenance: &'a Provenance,
    pub(super) outputs: Vec<(String, Format)>,
    #[serde(flatten)]
    pub(super) figures: serde_json::Value,
}

pub(super) fn provenance(
    p: Provenance,
    gpu: &photonmap::gpu::Gpu,
    method: &str,
    o: &RenderOptions,
) -> Provenance {
    let mut p = crate::cli::with_driver(p, gpu);
    p.method = method.into();
    let options = format!("{:?}", o.method);
    p.method_options = format!(
        "{:016x}",
        photonmap::provenance::fnv1a64(options.as_bytes())
    );
    (p.seed, p.spp, p.width, p.height) = (o.seed, o.spp, o.width, o.height);
    p.pixel_bounds = o.pixel_bounds.map(|b| [b.x0, b.x1, b.y0, b.y1]);
    p
}

pub(super) fn print_explain(lines: &[photonmap::render::ExplainLine]) {
    for l in lines {
        let what = if l.ran { "run " } else { "skip" };
        eprintln!("{what} {:<34} {:>6} passes  {}", l.stage, l.passes, l.why);
    }
}

/// Writes the final image to every output, all or none; returns what was written.
pub(super) fn write_images(
    image: &Image,
    outputs: &[(PathBuf, Format)],
    provenance: &Provenance,
) -> Result<Vec<(String, Format)>> {
    write_image_sets(&[(image, outputs)], provenance)
}

/// Each image to each of its outputs, all written or none: everything is
/// encoded first, and nothing is written where an image holds NaN or
/// infinite pixels.
pub(super) fn write_image_sets(
    sets: &[(&Image, &[(PathBuf, Format)])],
    provenance: &Provenance,
) -> Result<Vec<(String, Format)>> {
    let mut encoded: Vec<(&Path, Vec<u8>)> = Vec::new();
    for (image, outputs) in sets {
        if image.has_non_finite() {
            bail!("the render produced NaN or infinite pixels: nothing was written (a bug; please report it with the scene)");
        }
        for (p, f) in outputs.iter() {
            encoded.push((p.as_path(), f.encode(image, provenance)?));
        }
    }
    let files: Vec<(&Path, &[u8])> = encoded.iter().map(|(p, b)| (*p, b.as_slice())).collect();
    write_all_atomically(&files)?;
    Ok(sets
        .iter()
        .flat_map(|(_, outputs)| outputs.iter())
        .map(|(p, f)| (p.display().to_string(), *f))
        .collect())
}

pub(super) fn write_software_reference(
    out: &render::RenderOutput,
    scene: &Scene,
    path: &Path,
    quiet: bool,
) -> Result<()> {
    let wall = std::time::Instant::now();
    let img = render::software::software_image(out, scene)
        .ok_or_else(|| anyhow!("no photon map to estimate from"))?;
    write_atomically(path, &img.png_bytes()?)?;
    if !quiet {
        eprintln!(
            "software reference (kd-tree) in {:.2} s: wrote {}",
            wall.elapsed().as_secs_f64(),
            path.display()
        );
    }
    Ok(())
}
