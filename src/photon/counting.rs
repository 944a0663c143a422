//! The counting build: the sorted photon map of build A (the same pairs, cell
//! table and sorted records, `SortedPhotonMap`) in O(log n) passes instead of
//! the bitonic sort's O(log^2 n). A counting sort into the grid's slots:
//! 1. compaction of the stored records by HistoPyramid, in record order,
//!    which also counts each record into its slot's texel of a histogram
//!    (image atomics);
//! 2. prefix sums of the histogram by a second HistoPyramid (Ziegler, Tevs,
//!    Theobalt and Seidel 2006): the histogram is laid out in Z order
//!    (`glsl/common/zorder.glsl`), so one walk up the pyramid per slot gives
//!    the number of photons in the slots before it, the cell table that the
//!    bitonic build's binary search writes;
//! 3. one draw of a vertex a photon, clipped, that places each photon at its
//!    slot's next free index (an atomic count-down on the histogram);
//! 4. the bitonic build's gather of the records into sorted order.
//!
//! The vertices are drawn in record order. Where a draw's vertices are shaded
//! in order (llvmpipe: one thread, in order), each slot's photons then lie in
//! record order, as the bitonic sort leaves them, and the map is the bitonic
//! build's bit for bit (tested); on drivers that shade them out of order the
//! same photons lie in each slot, in an order that may change from run to run.

use crate::gpu::{DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture};
use crate::timing::Timings;

use super::bitonic::{gather_records, reduce_pyramid, sort_texture_size};
use super::{Grid, PhotonFrames, SortedPhotonMap, StageClock};

/// Mip levels of a HistoPyramid over a `w` x `h` power-of-two base.
fn pyramid_levels(w: u32, h: u32) -> u32 {
    32 - w.max(h).leading_zeros()
}

pub struct CountingBuild {
    gpu: Gpu,
    pyramid_base: Program,
    pyramid_reduce: Program,
    compact: Program,
    prefix: Program,
    place: Program,
    gather: Program,
}

impl CountingBuild {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        let record_order = [("RECORD_ORDER", "1".to_string())];
        Ok(Self {
            gpu: gpu.clone(),
            pyramid_base: Program::fullscreen_with(gpu, "photon/pyramid_base.frag", &record_order)?,
            pyramid_reduce: Program::fullscreen(gpu, "photon/pyramid_reduce.frag")?,
            compact: Program::fullscreen_with(gpu, "photon/compact.frag", &record_order)?,
            prefix: Program::fullscreen(gpu, "photon/prefix_first.frag")?,
            place: Program::new(gpu, "photon/place.vert", "photon/place.frag", &[])?,
            gather: Program::fullscreen(gpu, "photon/gather.frag")?,
        })
    }

    /// Step 1: the stored records' (slot, record) pairs in record order, and
    /// the histogram of their slots (level 0 of `counts`, zeroed here).
    fn compacted_pairs(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        counts: &Texture,
    ) -> Result<(Texture, u32)> {
        let (w, h) = sort_texture_size(frames.record_count() as u64);
        let levels = pyramid_levels(w, h);
        let pyramid = Texture::with_levels(&self.gpu, w, h, TexFormat::Rgba32I, levels)?;
        {
            let target = Target::for_level(&self.gpu, &pyramid, 0)?;
            let mut b = self.pyramid_base.bind();
            grid.bind(&mut b);
            frames.bind_records(&mut b);
            b.int("u_level_width", w as i32)
                .draw_fullscreen(&target, &DrawState::PLAIN)?;
        }
        reduce_pyramid(&self.gpu, &self.pyramid_reduce, &pyramid, levels)?;
        let count = pyramid.read_i32_texel(levels - 1)[0] as u32;
        Target::for_level(&self.gpu, counts, 0)?.clear_i32([0; 4]);
        let (cw, ch) = sort_texture_size(count.max(2) as u64);
        let pairs = Texture::new(&self.gpu, cw, ch, TexFormat::Rg32I)?;
        let target = Target::new(&self.gpu, &[&pairs])?;
        let mut b = self.compact.bind();
        grid.bind(&mut b);
        b.texture("u_pyramid", &pyramid)
            .int("u_top", levels as i32 - 1)
            .texture("u_position", &frames.position)
            .int("u_record_width", frames.width as i32)
            .int("u_out_width", cw as i32)
            .int("u_count", count as i32)
            .image_read_write("u_counts", counts)
            .draw_fullscreen(&target, &DrawState::PLAIN)?;
        self.gpu.image_barrier();
        self.gpu.check("compacting and counting stored photons")?;
        Ok((pairs, count))
    }

    /// The whole build from traced photon frames, with its stages timed.
    pub fn build(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        timings: &mut Timings,
    ) -> Result<SortedPhotonMap> {
        let query = Query::timer(&self.gpu)?;
        let slots = grid.slot_count();
        // The histogram: one texel a slot, in Z order, with its pyramid.
        let (hw, hh) = sort_texture_size(slots as u64);
        let levels = pyramid_levels(hw, hh);
        let counts = Texture::with_levels(&self.gpu, hw, hh, TexFormat::R32I, levels)?;

        let clock = StageClock::start(&self.gpu, &query);
        let (pairs, count) = self.compacted_pairs(frames, grid, &counts)?;
        let record_levels = {
            let (w, h) = sort_texture_size(frames.record_count() as u64);
            pyramid_levels(w, h)
        };
        clock.stop(timings, "compact and count", record_levels as usize + 1);

        let clock = StageClock::start(&self.gpu, &query);
        reduce_pyramid(&self.gpu, &self.pyramid_reduce, &counts, levels)?;
        let entries = slots as u64 + 1;
        let grid_width = (entries as f64).sqrt().ceil() as u32;
        let grid_height = entries.div_ceil(grid_width as u64) as u32;
        let grid_first = Texture::new(&self.gpu, grid_width, grid_height, TexFormat::Rgba32I)?;
        {
            let target = Target::new(&self.gpu, &[&grid_first])?;
            self.prefix
                .bind()
                .texture("u_pyramid", &counts)
                .int("u_top", levels as i32 - 1)
                .int("u_grid_width", grid_width as i32)
                .int("u_cell_count", slots as i32)
                .draw_fullscreen(&target, &DrawState::PLAIN)?;
        }
        self.gpu.check("prefix sums of the slot histogram")?;
        clock.stop(timings, "prefix sums", levels as usize);

        let (w, h) = (pairs.width, pairs.height);
        let sorted = Texture::new(&self.gpu, w, h, TexFormat::Rg32I)?;
        let clock = StageClock::start(&self.gpu, &query);
        Target::new(&self.gpu, &[&sorted])?.clear_i32([crate::layout::INVALID_KEY, 0, 0, 0]);
        // Every vertex stores through images and is clipped: the draw needs
        // a target, not its texels.
        let unused = Texture::new(&self.gpu, 1, 1, TexFormat::R32I)?;
        let points = Target::new(&self.gpu, &[&unused])?;
        self.place
            .bind()
            .texture("u_pairs", &pairs)
            .int("u_pairs_width", w as i32)
            .texture("u_grid_first", &grid_first)
            .int("u_grid_width", grid_width as i32)
            .image_read_write("u_counts", &counts)
            .image("u_sorted", &sorted)
            .int("u_sorted_width", w as i32)
            .draw_points(&points, &DrawState::NO_COLOR, 0, count as i32)?;
        self.gpu.image_barrier();
        self.gpu.check("placing photons")?;
        clock.stop(timings, "place", 1);

        let clock = StageClock::start(&self.gpu, &query);
        let map = gather_records(
            &self.gpu,
            &self.gather,
            frames,
            sorted,
            grid_first,
            grid_width,
            grid,
        )?;
        clock.stop(timings, "gather", 1);
        Ok(map)
    }
}
