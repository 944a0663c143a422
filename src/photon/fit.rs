//! Grid bounds fitted to where photons actually land (a min/max reduction of
//! the stored photons on the GPU), for scenes that do not fix them: cells then
//! cover the photons, not the whole scene (the paper's 250 x 1 x 250 floor grids).

use glam::Vec3;

use crate::scene::defaults::MAX_GRID_SIDE;

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};

use super::{Grid, PhotonFrames};

/// The grid a scene's photon map uses: the bounds the scene fixes, else the
/// box of the stored photons (`fitted_grid`), else the scene's own box. Every
/// build (render, `photonmap photons`) takes its grid from here.
pub fn grid_for(gpu: &Gpu, scene: &crate::scene::Scene, frames: &PhotonFrames) -> Result<Grid> {
    if scene.photon_map.grid_bounds.is_some() {
        return Ok(Grid::for_scene(scene));
    }
    Ok(match photon_bounds(gpu, frames)? {
        Some(b) => fitted_grid(
            b,
            scene.size(),
            scene.photon_map.grid_resolution,
            scene.photon_map.max_radius,
        ),
        None => Grid::for_scene(scene),
    })
}

/// The box of the stored photons in use, or None if there are none.
pub fn photon_bounds(gpu: &Gpu, frames: &PhotonFrames) -> Result<Option<(Vec3, Vec3)>> {
    let base = Program::fullscreen(gpu, "photon/bounds_base.frag")?;
    let reduce = Program::fullscreen(gpu, "photon/bounds_reduce.frag")?;
    let (mut w, mut h) = (frames.width, frames.frame_height * frames.frames);
    let mut lo = Texture::new(gpu, w, h, TexFormat::Rgba32F)?;
    let mut hi = Texture::new(gpu, w, h, TexFormat::Rgba32F)?;
    {
        let target = Target::new(gpu, &[&lo, &hi])?;
        base.bind()
            .texture("u_position", &frames.position)
            .texture("u_power", &frames.power)
            .int("u_record_width", frames.width as i32)
            .int("u_frame_height", frames.frame_height as i32)
            .int("u_photons_used", frames.photons_used as i32)
            .draw_fullscreen(&target, &DrawState::PLAIN)?;
    }
    while w > 1 || h > 1 {
        (w, h) = (w.div_ceil(2), h.div_ceil(2));
        let (nlo, nhi) = (
            Texture::new(gpu, w, h, TexFormat::Rgba32F)?,
            Texture::new(gpu, w, h, TexFormat::Rgba32F)?,
        );
        {
            let target = Target::new(gpu, &[&nlo, &nhi])?;
            reduce
                .bind()
                .texture("u_min", &lo)
                .texture("u_max", &hi)
                .draw_fullscreen(&target, &DrawState::PLAIN)?;
        }
        (lo, hi) = (nlo, nhi);
    }
    gpu.check("photon bounds")?;
    let (l, u) = (lo.read_f32(), hi.read_f32());
    let (l, u) = (Vec3::new(l[0], l[1], l[2]), Vec3::new(u[0], u[1], u[2]));
    Ok((l.cmple(u).all()).then_some((l, u)))
}

/// The grid over the photons' box, padded by a thousandth of the scene's size,
/// each side at least that thick (a floor's photons lie in a plane). It keeps
/// the requested number of cells but shapes them to the box: the kNN-grid's
/// cubic shells need roughly cubic cells. (A 64^3 grid squeezed onto a floor's
/// thin slab made cells 400 times wider than tall, and GLASS BALL's estimate
/// took 354 s instead of 0.9.) An axis thinner than a cell gets one cell.
pub fn fitted_grid(
    bounds: (Vec3, Vec3),
    scene_size: f32,
    resolution: [u32; 3],
    max_radius: f32,
) -> Grid {
    let pad = 1e-3 * scene_size;
    let (lo, hi) = (bounds.0 - Vec3::splat(pad), bounds.1 + Vec3::splat(pad));
    let hi = hi.max(lo + Vec3::splat(2.0 * pad));
    let shaped = shaped_resolution(hi - lo, resolution.iter().map(|&r| r as f64).product());
    // No cell narrower than a quarter of the maximum radius: finer cells only
    // add empty cells for the search to walk (a 0.25 radius over 0.011 cells
    // walked ~22 shells; 5.2 s against 0.9 s).
    let extent = hi - lo;
    let cap = |a: usize| ((extent[a] / (0.25 * max_radius)).ceil() as u32).max(1);
    Grid {
        min: lo,
        max: hi,
        resolution: std::array::from_fn(|a| shaped[a].min(cap(a))),
        storage: super::GridStorage::Uniform,
    }
}

/// Cells per axis for a box of `extent` with about `cells` cells of even shape.
pub fn shaped_resolution(extent: Vec3, cells: f64) -> [u32; 3] {
    let e = [extent.x as f64, extent.y as f64, extent.z as f64];
    let mut active = [true; 3];
    let mut side = 0.0;
    // Drop axes thinner than a cell, then share the cells among the rest.
    for _ in 0..3 {
        let d = active.iter().filter(|&&a| a).count();
        if d == 0 {
            break;
        }
        let volume: f64 = (0..3).filter(|&a| active[a]).map(|a| e[a]).product();
        side = (volume / cells).powf(1.0 / d as f64);
        let mut changed = false;
        for a in 0..3 {
            if active[a] && e[a] < side {
                active[a] = false;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    std::array::from_fn(|a| {
        if active[a] && side > 0.0 {
            ((e[a] / side).round() as u32).clamp(1, MAX_GRID_SIDE as u32)
        } else {
            1
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_take_the_shape_of_the_box() {
        // A floor: 6 x 0.012 x 6 with 64^3 cells -> a flat grid of square cells.
        let r = shaped_resolution(Vec3::new(6.0, 0.012, 6.0), 64.0f64.powi(3));
        assert_eq!(r[1], 1);
        assert_eq!(r[0], r[2]);
        assert!(
            (r[0] as f64 * r[2] as f64 - 262144.0).abs() < 262144.0 * 0.02,
            "{r:?}"
        );
        // A cube keeps its cells.
        assert_eq!(
            shaped_resolution(Vec3::splat(2.0), 64.0f64.powi(3)),
            [64, 64, 64]
        );
        // A long box: cells stay cubic.
        let r = shaped_resolution(Vec3::new(8.0, 2.0, 2.0), 32.0 * 8.0 * 8.0);
        assert_eq!(r, [32, 8, 8]);
    }
}
