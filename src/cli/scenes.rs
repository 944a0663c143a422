//! `photonmap scenes`: the scenes compiled into the binary, usable by name.

use anyhow::Result;
use clap::Args;

use photonmap::scene::embedded;

/// List the embedded scenes (render them by name: `photonmap render ring -o ring.png`).
#[derive(Args)]
pub struct ScenesArgs {
    /// As JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &ScenesArgs) -> Result<()> {
    let mut rows = Vec::new();
    for name in embedded::names() {
        let scene = embedded::load(name)?;
        rows.push(serde_json::json!({
            "name": name,
            "title": scene.name,
            "width": scene.camera.width,
            "height": scene.camera.height,
            "shapes": scene.shapes.len(),
            "lights": scene.lights.len(),
            "photons_stored": scene.photon_map.photons_stored,
        }));
    }
    if args.json {
        return super::print_json(&rows);
    }
    for r in &rows {
        println!(
            "{:<36} {:<14} {:>4} x {:<4} {:>4} shapes {:>6} photons",
            r["name"].as_str().unwrap_or(""),
            r["title"].as_str().unwrap_or(""),
            r["width"],
            r["height"],
            r["shapes"],
            r["photons_stored"]
        );
    }
    Ok(())
}
