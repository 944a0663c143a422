//! `photonmap convert-scene`: a pbrt-v4 or Mitsuba 3 scene written as the
//! TOML scene photonmap understood, to read and edit the mapping.

use std::path::PathBuf;

use anyhow::{bail, Result};
use clap::Args;

use photonmap::image::write_atomically;
use photonmap::scene::import::{self, ImportOptions};

/// Write a pbrt-v4 (.pbrt) or Mitsuba 3 (.xml) scene as photonmap's TOML.
#[derive(Args)]
pub struct ConvertSceneArgs {
    /// The scene: .pbrt or .xml.
    pub input: PathBuf,
    /// The TOML scene to write (.toml); nothing is written if the scene is refused.
    pub output: PathBuf,
    /// Map what photonmap cannot render to the nearest thing it can, one
    /// line each on stderr, instead of refusing it.
    #[arg(long)]
    pub lenient: bool,
    /// A Mitsuba parameter: sets `$KEY` and `<default name="KEY">` (repeatable).
    #[arg(short = 'D', value_name = "KEY=VALUE", value_parser = define)]
    pub define: Vec<(String, String)>,
}

fn define(s: &str) -> Result<(String, String), String> {
    match s.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.to_string())),
        _ => Err(format!("{s}: give KEY=VALUE")),
    }
}

pub fn run(a: &ConvertSceneArgs) -> Result<()> {
    if import::format_of(&a.input).is_none() {
        bail!("{}: the scene must end in .pbrt or .xml", a.input.display());
    }
    super::check_output(&a.output, "toml", "OUT")?;
    let opts = ImportOptions {
        lenient: a.lenient,
        defines: a.define.clone(),
    };
    let converted = import::convert_file(&a.input, &opts)?;
    // What is written must load: the TOML loader checks it first.
    let name = PathBuf::from(format!("{} as TOML", a.input.display()));
    photonmap::scene::load_scene_str(&converted.toml, &name)?;
    for n in &converted.notes {
        eprintln!("note: {n}");
    }
    write_atomically(&a.output, converted.toml.as_bytes())?;
    Ok(())
}
