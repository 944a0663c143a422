//! `photonmap merge --tiles OUT.exr TILE.exr...`: the crops of one render
//! (`render --crop-window` or `--pixel-bounds`) stitched into its frame.
//! Pixel and photon streams are the frame's in every crop, so the stitched
//! image equals the render of the whole frame bit for bit. Each tile is
//! placed by its EXR data window; the tiles must cover the frame exactly
//! once and be crops of one render: the same provenance but for their
//! pixel bounds.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};

use photonmap::image::write_atomically;
use photonmap::render::Image;

/// The provenance fields that must agree between tiles of one render.
const SAME: [&str; 11] = [
    "scene_hash",
    "overrides",
    "method",
    "method_options",
    "seed",
    "spp",
    "iterations",
    "width",
    "height",
    "photons_emitted",
    "commit",
];

/// One tile: its pixels, where they go, and its provenance.
struct Tile {
    path: PathBuf,
    image: Image,
    origin: (u32, u32),
    provenance: serde_json::Value,
}

fn read_tile(path: &Path) -> Result<Tile> {
    let (attributes, provenance) = Image::exr_provenance(path)?;
    if attributes
        .iter()
        .any(|(k, v)| k == "partial" && v == "true")
    {
        bail!(
            "{}: a partial image: a tile must be finished",
            path.display()
        );
    }
    let image = Image::read_exr(path)?;
    let ((x, y), (fw, fh)) = Image::exr_placement(path)?;
    let frame = (provenance["width"].as_u64(), provenance["height"].as_u64());
    if frame != (Some(fw), Some(fh)) {
        bail!(
            "{}: its display window is {fw} x {fh} but its provenance's frame is {} x {}",
            path.display(),
            provenance["width"],
            provenance["height"]
        );
    }
    let inside = x >= 0
        && y >= 0
        && x as u64 + u64::from(image.width) <= fw
        && y as u64 + u64::from(image.height) <= fh;
    if !inside {
        bail!(
            "{}: its {} x {} pixels at ({x}, {y}) leave the {fw} x {fh} frame",
            path.display(),
            image.width,
            image.height
        );
    }
    Ok(Tile {
        path: path.to_path_buf(),
        image,
        origin: (x as u32, y as u32),
        provenance,
    })
}

/// Refuses tiles that are not crops of one render.
fn check_tiles(tiles: &[Tile]) -> Result<()> {
    let first = &tiles[0];
    for t in &tiles[1..] {
        require_same(
            &SAME,
            (&first.path, &first.provenance),
            (&t.path, &t.provenance),
            "tiles of one render",
        )?;
        if first.provenance["renderer"] != t.provenance["renderer"]
            || first.provenance["gl_version"] != t.provenance["gl_version"]
        {
            eprintln!(
                "note: {} and {} were rendered on different drivers ({} and {}): the seams may show",
                first.path.display(),
                t.path.display(),
                first.provenance["renderer"],
                t.provenance["renderer"]
            );
        }
    }
    Ok(())
}

/// Refuses two inputs whose provenance differs in any of `fields`: they are
/// not `what` (tiles of one render, passes of one frame).
pub(super) fn require_same(
    fields: &[&str],
    (a_path, a): (&Path, &serde_json::Value),
    (b_path, b): (&Path, &serde_json::Value),
    what: &str,
) -> Result<()> {
    for field in fields {
        let (x, y) = (&a[field], &b[field]);
        if x != y {
            bail!(
                "{} and {}: {field} differs ({x} and {y}): not {what}",
                a_path.display(),
                b_path.display()
            );
        }
    }
    Ok(())
}

/// The frame, each tile's pixels in place; refuses overlaps and gaps.
fn stitch(tiles: &[Tile]) -> Result<Image> {
    let w = tiles[0].provenance["width"].as_u64().unwrap_or(0) as u32;
    let h = tiles[0].provenance["height"].as_u64().unwrap_or(0) as u32;
    let mut frame = Image::new(w, h);
    let mut owner: Vec<Option<usize>> = vec![None; (w * h) as usize];
    for (i, t) in tiles.iter().enumerate() {
        for row in 0..t.image.height {
            for col in 0..t.image.width {
                let (x, y) = (t.origin.0 + col, t.origin.1 + row);
                let at = (y * w + x) as usize;
                if let Some(j) = owner[at] {
                    bail!(
                        "{} and {} overlap (pixel {x}, {y}): each pixel must come from one tile",
                        tiles[j].path.display(),
                        t.path.display()
                    );
                }
                owner[at] = Some(i);
                frame.pixels[at] = t.image.pixels[(row * t.image.width + col) as usize];
            }
        }
    }
    let missing = owner.iter().filter(|o| o.is_none()).count();
    if let Some(first) = owner.iter().position(Option::is_none) {
        bail!(
            "the tiles leave {missing} of the frame's {} pixels uncovered, the first at ({}, {})",
            w * h,
            first as u32 % w,
            first as u32 / w
        );
    }
    Ok(frame)
}

pub fn run(output: &Path, inputs: &[PathBuf], json: bool) -> Result<()> {
    let tiles = inputs
        .iter()
        .map(|p| read_tile(p))
        .collect::<Result<Vec<_>>>()?;
    check_tiles(&tiles)?;
    let frame = stitch(&tiles)?;
    let mut provenance = tiles[0].provenance.clone();
    if let Some(p) = provenance.as_object_mut() {
        p.remove("pixel_bounds");
    }
    let merged = serde_json::json!({
        "mode": "tiles",
        "inputs": inputs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>(),
        "origins": tiles.iter().map(|t| [t.origin.0, t.origin.1]).collect::<Vec<_>>(),
        "width": frame.width,
        "height": frame.height,
    });
    let attributes = vec![
        ("photonmap.merge".to_string(), merged.to_string()),
        ("photonmap.provenance".to_string(), provenance.to_string()),
    ];
    write_atomically(output, &frame.exr_bytes_with(&attributes)?)?;
    if json {
        crate::cli::print_json(&merged)?;
    } else {
        eprintln!(
            "stitched {} tiles into the {} x {} frame: {}",
            tiles.len(),
            frame.width,
            frame.height,
            output.display()
        );
    }
    Ok(())
}
