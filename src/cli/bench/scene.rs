//! The scene a method benchmark renders and the SPPM reference it is scored
//! against: where a scene's reference is found, and the scale that renders
//! at the reference's size.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Args;

use photonmap::render::Image;
use photonmap::scene::{embedded, Scene};

use super::output::stem;
use super::reference::read_reference;
use crate::cli::args::in_range;

/// The seed of every method benchmark's renders (`bench accuracy`'s first
/// of its seeds), so that their images compare across benchmarks.
pub const SEED: u32 = 7;

/// The scene a method benchmark renders, and its reference.
#[derive(Args)]
pub struct BenchScene {
    /// Scene file or embedded name.
    #[arg(long, required_unless_present = "triangles")]
    pub scene: Option<PathBuf>,
    /// Render `bench meshes`'s stage instead, its ball a mesh of about this
    /// many triangles (1024..=4194304).
    #[arg(long, value_name = "N", value_parser = in_range(1024, 1 << 22), conflicts_with = "scene")]
    pub triangles: Option<u32>,
    /// SPPM reference EXR (default: the scene's, as `bench accuracy` finds it;
    /// none for the mesh stage). Images render at its size.
    #[arg(long)]
    pub reference: Option<PathBuf>,
}

/// The reference `bench accuracy` looks for: photonmap-out/reference/ first,
/// then the committed reference_images/.
pub fn default_reference(scene: &Path) -> PathBuf {
    let name = format!("{}.sppm.exr", stem(scene));
    let made = crate::cli::out_dir("reference").join(&name);
    if made.is_file() {
        made
    } else {
        PathBuf::from("reference_images").join(name)
    }
}

/// How many times the scene's width is the reference's (at `path`): the
/// scale every render takes to be the reference's size.
pub fn reference_scale(path: &Path, reference: &Image, scene: &Scene) -> Result<u32> {
    if reference.width == 0 || !scene.camera.width.is_multiple_of(reference.width) {
        bail!(
            "{}: {} x {} pixels is not the scene's {} x {} divided by a whole number",
            path.display(),
            reference.width,
            reference.height,
            scene.camera.width,
            scene.camera.height
        );
    }
    Ok(scene.camera.width / reference.width)
}

/// A method benchmark's scene, loaded, with its SPPM reference.
pub struct Loaded {
    pub scene: Scene,
    /// Its name in output folders: the file stem, or `stage_<triangles>`.
    pub name: String,
    /// The reference's path and image, when there is one.
    pub reference: Option<(PathBuf, Image)>,
    /// The reference's scale below the scene's resolution (1 without one).
    pub scale: u32,
}

impl BenchScene {
    /// The scene (a file or embedded name, or `bench meshes`' stage of about
    /// `triangles` triangles) and its SPPM reference when there is one
    /// (given, or the scene's as `bench accuracy` finds it; none for the
    /// stage).
    pub fn load(&self) -> Result<Loaded> {
        let (scene, name): (Scene, String) = match (self.triangles, &self.scene) {
            (Some(n), _) => (super::meshes::stage(n)?, format!("stage_{n}")),
            (None, Some(s)) => (embedded::load_path_or_name(s)?, stem(s)),
            (None, None) => bail!("give --scene or --triangles"),
        };
        let reference = match (&self.reference, &self.scene) {
            (Some(r), _) => Some(r.clone()),
            (None, Some(s)) if self.triangles.is_none() => {
                Some(default_reference(s)).filter(|r| r.is_file())
            }
            _ => None,
        };
        let reference = reference
            .map(|r| -> Result<(PathBuf, Image)> { Ok((r.clone(), read_reference(&r)?.0)) })
            .transpose()?;
        let scale = match &reference {
            Some((path, img)) => reference_scale(path, img, &scene)?,
            None => 1,
        };
        Ok(Loaded {
            scene,
            name,
            reference,
            scale,
        })
    }
}
