//! `photonmap merge --passes OUT.exr IN.exr...`: independent renders of one
//! frame (other seeds, other machines) averaged into one image, each weighted
//! by its eye samples a pixel, with the variance of the mean beside it.
//!
//! The inputs must be photonmap's own EXRs of the same scene text, overrides,
//! method and method options, size and (SPPM) iterations, each with a seed
//! of its own, and none a merge itself or a partial image of unknown samples
//! (what `--on-signal write-partial` writes counts its samples, and is used). Averaging K independent runs leaves their bias as it is,
//! SPPM's included (each run has the same expectation), and divides their
//! variance by K, so their noise by sqrt(K).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
use clap::Args;

use photonmap::image::write_atomically;
use photonmap::render::Image;

/// Merge renders of one frame into OUT.exr. `--passes`: independent runs
/// (other seeds), averaged by their eye samples, with the variance of the
/// mean as a second layer and the noise before and after; inputs of another
/// scene, overrides, method, size or SPPM iteration count, repeated seeds and
/// partial images of unknown samples are refused. `--tiles`: crops of one
/// render (`render --crop-window` or `--pixel-bounds`), placed by their data
/// windows into the frame; gaps, overlaps and tiles of different renders are
/// refused. Nothing is written when an input is refused.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("mode").required(true).args(["passes", "tiles"])))]
pub struct MergeArgs {
    /// Independent runs of the same frame, averaged.
    #[arg(long)]
    pub passes: bool,
    /// Tiles of one render, stitched into its frame.
    #[arg(long)]
    pub tiles: bool,
    /// The merged EXR.
    pub output: PathBuf,
    /// The renders' EXRs (two or more passes; one or more tiles).
    #[arg(required = true, num_args = 1..)]
    pub inputs: Vec<PathBuf>,
    /// Print the merge's figures (inputs, seeds, weights, noise) as JSON.
    #[arg(long)]
    pub json: bool,
}

/// One input: its pixels and what its header says of it.
struct Pass {
    path: PathBuf,
    image: Image,
    provenance: serde_json::Value,
    weight: f64,
}

/// The provenance fields that must agree between passes of one frame.
const SAME: [&str; 7] = [
    "scene_hash",
    "overrides",
    "method",
    "method_options",
    "width",
    "height",
    "iterations",
];

fn read_pass(path: &Path) -> Result<Pass> {
    let (attributes, provenance) = Image::exr_provenance(path)?;
    if provenance["pixel_bounds"].is_array() {
        bail!(
            "{}: a tile (a crop of the frame): stitch the tiles with merge --tiles first",
            path.display()
        );
    }
    let merged_passes = attributes
        .iter()
        .any(|(k, v)| k == "photonmap.merge" && v.contains("\"mode\":\"passes\""));
    if merged_passes {
        bail!(
            "{}: already a merge of passes: merge its passes together instead",
            path.display()
        );
    }
    // `--on-signal write-partial` records the samples it holds (and sets
    // spp or iterations to them); `--write-partial`'s file does not.
    let partial = attributes
        .iter()
        .any(|(k, v)| k == "partial" && v == "true");
    let counted = attributes
        .iter()
        .any(|(k, _)| k == "photonmap.samples_done");
    if partial && !counted {
        bail!(
            "{}: a partial image (--write-partial's file): its samples are not known",
            path.display()
        );
    }
    let progressive = provenance["method"] == "sppm" || provenance["method"] == "vcm";
    if progressive && provenance["iterations"].is_null() {
        bail!("{}: a progressive (SPPM or VCM) render whose header does not record its iterations (a --write-partial file?): passes of different lengths cannot be told apart", path.display());
    }
    let weight = provenance["spp"]
        .as_f64()
        .filter(|s| *s >= 1.0)
        .unwrap_or(1.0);
    Ok(Pass {
        path: path.to_path_buf(),
        image: Image::read_exr(path)?,
        provenance,
        weight,
    })
}

/// Refuses passes that are not independent runs of one frame.
fn check_passes(passes: &[Pass]) -> Result<()> {
    let first = &passes[0];
    for p in &passes[1..] {
        super::merge_tiles::require_same(
            &SAME,
            (&first.path, &first.provenance),
            (&p.path, &p.provenance),
            "passes of one frame",
        )?;
        if (p.image.width, p.image.height) != (first.image.width, first.image.height) {
            bail!(
                "{} and {}: the images' sizes differ",
                first.path.display(),
                p.path.display()
            );
        }
    }
    for (i, a) in passes.iter().enumerate() {
        for b in &passes[i + 1..] {
            if a.provenance["seed"] == b.provenance["seed"] {
                bail!(
                    "{} and {}: both seed {}: the same seed renders the same image, not an independent pass",
                    a.path.display(),
                    b.path.display(),
                    a.provenance["seed"]
                );
            }
        }
    }
    Ok(())
}

/// The weighted mean and, per pixel and channel, the variance of that mean
/// from the passes' spread: sum w (x - mean)^2 / ((K - 1) sum w), which for
/// equal weights is the sample variance over K.
fn merge(passes: &[Pass]) -> (Image, Vec<[f32; 3]>) {
    let (w, h) = (passes[0].image.width, passes[0].image.height);
    let total: f64 = passes.iter().map(|p| p.weight).sum();
    let k = passes.len() as f64;
    let mut mean = Image::new(w, h);
    let mut variance = vec![[0f32; 3]; (w * h) as usize];
    for (i, (m_px, v_px)) in mean.pixels.iter_mut().zip(&mut variance).enumerate() {
        for (c, (m_out, v_out)) in m_px.iter_mut().zip(v_px.iter_mut()).enumerate() {
            let value = |p: &Pass| f64::from(p.image.pixels[i][c]);
            let m = passes.iter().map(|p| p.weight * value(p)).sum::<f64>() / total;
            let spread: f64 = passes
                .iter()
                .map(|p| p.weight * (value(p) - m).powi(2))
                .sum();
            *m_out = m as f32;
            *v_out = (spread / ((k - 1.0) * total)) as f32;
        }
    }
    (mean, variance)
}

/// The EXR: layer "rgb" (the mean, with the provenance) and layer "variance".
fn merged_exr(
    mean: &Image,
    variance: &[[f32; 3]],
    attributes: &[(String, String)],
) -> Result<Vec<u8>> {
    use exr::prelude::*;
    let size = (mean.width as usize, mean.height as usize);
    let channels = |of: &dyn Fn(usize, usize) -> f32| {
        let channel = |name: &str, c: usize| {
            AnyChannel::new(
                name,
                FlatSamples::F32((0..size.0 * size.1).map(|i| of(i, c)).collect()),
            )
        };
        AnyChannels::sort(SmallVec::from_vec(vec![
            channel("R", 0),
            channel("G", 1),
            channel("B", 2),
        ]))
    };
    let mut rgb_attributes = LayerAttributes::named("rgb");
    for (k, v) in attributes {
        if let (Some(k), Some(v)) = (Text::new_or_none(k), Text::new_or_none(v)) {
            rgb_attributes.other.insert(k, AttributeValue::Text(v));
        }
    }
    let layers: Layers<_> = SmallVec::from_vec(vec![
        Layer::new(
            size,
            rgb_attributes,
            Encoding::SMALL_LOSSLESS,
            channels(&|i, c| mean.pixels[i][c]),
        ),
        Layer::new(
            size,
            LayerAttributes::named("variance"),
            Encoding::SMALL_LOSSLESS,
            channels(&|i, c| variance[i][c]),
        ),
    ]);
    let image = exr::image::Image::from_layers(
        ImageAttributes::new(IntegerBounds::from_dimensions(size)),
        layers,
    );
    let mut out = std::io::Cursor::new(Vec::new());
    image
        .write()
        .to_buffered(&mut out)
        .context("encoding the merged EXR")?;
    Ok(out.into_inner())
}

/// The root-mean-square standard error over the image, over its mean.
fn relative_noise(variance: &[[f32; 3]], image: &Image) -> f64 {
    let n = (variance.len() * 3) as f64;
    let v: f64 = variance
        .iter()
        .flatten()
        .map(|&x| f64::from(x))
        .sum::<f64>()
        / n;
    let mean: f64 = image.mean().iter().sum::<f64>() / 3.0;
    if mean > 0.0 {
        v.sqrt() / mean
    } else {
        0.0
    }
}

pub fn run(a: &MergeArgs) -> Result<()> {
    crate::cli::check_output(&a.output, "exr", "merge")?;
    if a.inputs.iter().any(|i| i == &a.output) {
        bail!(
            "merge {}: also an input; write the merged image to a file of its own",
            a.output.display()
        );
    }
    if a.tiles {
        return super::merge_tiles::run(&a.output, &a.inputs, a.json);
    }
    if a.inputs.len() < 2 {
        bail!("merge --passes: give two or more passes");
    }
    let passes = a
        .inputs
        .iter()
        .map(|p| read_pass(p))
        .collect::<Result<Vec<_>>>()?;
    check_passes(&passes)?;
    let (mean, variance) = merge(&passes);
    let k = passes.len();
    let noise = relative_noise(&variance, &mean);
    // One pass of the mean weight has K times the merged variance.
    let noise_one = noise * (k as f64).sqrt();
    let seeds: Vec<&serde_json::Value> = passes.iter().map(|p| &p.provenance["seed"]).collect();
    let merged = serde_json::json!({
        "mode": "passes",
        "inputs": a.inputs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        "seeds": seeds,
        "weights": passes.iter().map(|p| p.weight).collect::<Vec<_>>(),
        "relative_noise": noise,
        "relative_noise_of_one_pass": noise_one,
    });
    let mut attributes = vec![(
        "photonmap.provenance".to_string(),
        passes[0].provenance.to_string(),
    )];
    attributes.push(("photonmap.merge".to_string(), merged.to_string()));
    let bytes = merged_exr(&mean, &variance, &attributes)
        .with_context(|| format!("merge {}", a.output.display()))?;
    write_atomically(&a.output, &bytes)?;
    if a.json {
        crate::cli::print_json(&merged)?;
    } else {
        eprintln!(
            "merged {k} passes into {}: noise (root-mean-square standard error over the image's mean) {noise:.4}, one pass {noise_one:.4}; bias is that of each pass",
            a.output.display()
        );
    }
    Ok(())
}
