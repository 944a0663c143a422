//! `photonmap compare`: error metrics between two linear images.

use std::path::PathBuf;

use anyhow::{anyhow, bail, Result};
use clap::Args;

use photonmap::image::write_atomically;
use photonmap::metrics::{compare, false_colour};
use photonmap::render::Image;

/// Compare two linear EXR images (the second is the reference): RMSE,
/// relative MSE, SSIM, and optionally a false-colour difference image.
#[derive(Args)]
pub struct CompareArgs {
    pub image: PathBuf,
    pub reference: PathBuf,
    /// Only pixels where this PNG (same size) is bright (> 50%) count.
    #[arg(long)]
    pub mask: Option<PathBuf>,
    /// Write |a - b| / (|b| + 0.01) as a false-colour PNG (black 0 .. red >= 1).
    #[arg(long, value_name = "PNG")]
    pub diff: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &CompareArgs) -> Result<()> {
    if let Some(d) = &args.diff {
        super::check_output(d, "png", "--diff")?;
    }
    let a = Image::read_exr(&args.image)?;
    let b = Image::read_exr(&args.reference)?;
    let mask = args.mask.as_ref().map(|p| read_mask(p, &a)).transpose()?;
    let metrics = compare(&a, &b, mask.as_deref())?;
    if let Some(d) = &args.diff {
        write_atomically(d, &false_colour(&a, &b).png_bytes()?)?;
    }
    if args.json {
        return super::print_json(&metrics);
    }
    println!("pixels compared  {}", metrics.pixels_compared);
    println!("RMSE (linear)    {:.6}", metrics.rmse);
    println!("relative MSE     {:.6}", metrics.rel_mse);
    println!("SSIM (luminance) {:.6}", metrics.ssim);
    Ok(())
}

/// A PNG mask of the image's size: bright pixels count.
fn read_mask(path: &std::path::Path, image: &Image) -> Result<Vec<bool>> {
    let m = ::image::open(path)
        .map_err(|e| anyhow!("cannot read the mask {}: {e}", path.display()))?
        .to_luma8();
    if m.dimensions() != (image.width, image.height) {
        bail!(
            "--mask {}: {} x {} pixels, the images are {} x {}",
            path.display(),
            m.width(),
            m.height(),
            image.width,
            image.height
        );
    }
    Ok(m.pixels().map(|p| p[0] > 127).collect())
}
