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

use super::bitonic::{cell_table_size, gather_records};
use super::compaction::{pyramid_levels, sort_texture_size, Compaction};
use super::{Grid, PhotonFrames, SortedPhotonMap, StageClock};

pub struct CountingBuild {
    gpu: Gpu,
    compaction: Compaction,
    prefix: Program,
    place: Program,
    gather: Program,
    /// What the placement draws into: nothing (every vertex is clipped and
    /// stores through images), but a draw needs a target.
    no_pixels: (Texture, Target),
}

impl CountingBuild {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        let unused = Texture::new(gpu, 1, 1, TexFormat::R32I)?;
        let target = Target::new(gpu, &[&unused])?;
        Ok(Self {
            gpu: gpu.clone(),
            compaction: Compaction::new(gpu, &[], true)?,
            prefix: Program::fullscreen(gpu, "photon/prefix_first.frag")?,
            place: Program::new(gpu, "photon/place.vert", "photon/place.frag", &[])?,
            gather: Program::fullscreen(gpu, "photon/gather.frag")?,
            no_pixels: (unused, target),
        })
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
        let compacted = self.compaction.pairs(frames, grid, Some(&counts))?;
        clock.stop(timings, "compact and count", compacted.passes as usize);
        let (pairs, count) = (compacted.pairs, compacted.count);

        let clock = StageClock::start(&self.gpu, &query);
        self.compaction.reduce(&counts, levels)?;
        let (grid_width, grid_height) = cell_table_size(slots);
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
        self.place
            .bind()
            .texture("u_pairs", &pairs)
            .int("u_pairs_width", w as i32)
            .texture("u_grid_first", &grid_first)
            .int("u_grid_width", grid_width as i32)
            .image_read_write("u_counts", &counts)
            .image("u_sorted", &sorted)
            .int("u_sorted_width", w as i32)
            .draw_points(&self.no_pixels.1, &DrawState::NO_COLOR, 0, count as i32)?;
        self.gpu.image_barrier();
        self.gpu.check("placing photons")?;
        clock.stop(timings, "place", 1);

        let clock = StageClock::start(&self.gpu, &query);
        let map = gather_records(
            &self.gpu,
            &self.gather,
            frames,
            (sorted, Some(count)),
            (grid_first, grid_width),
            grid,
        )?;
        clock.stop(timings, "gather", 1);
        Ok(map)
    }
}
