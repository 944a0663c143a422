//! `photonmap convert`: an EXR or PFM image into another format by extension
//! (PNG in sRGB, EXR or PFM in linear float), e.g. to look at a reference.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use photonmap::image::write_atomically;
use photonmap::render::Image;

/// Convert a linear image (EXR) to PNG (sRGB), EXR or PFM, by the output's extension.
#[derive(Args)]
pub struct ConvertArgs {
    pub input: PathBuf,
    pub output: PathBuf,
    /// Multiply linear values by this before writing (exposure).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f32,
}

pub fn run(a: &ConvertArgs) -> Result<()> {
    let mut img = Image::read_exr(&a.input)?;
    for p in &mut img.pixels {
        for c in p.iter_mut() {
            *c *= a.scale;
        }
    }
    let ext = a
        .output
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let bytes = match ext.as_str() {
        "png" => img.png_bytes()?,
        "exr" => img.exr_bytes()?,
        "pfm" => img.pfm_bytes(),
        _ => bail!(
            "{}: the file name must end in .png, .exr or .pfm",
            a.output.display()
        ),
    };
    write_atomically(&a.output, &bytes)?;
    Ok(())
}
