//! Build A (section 2.2.1): a (cell, record) key per photon record, bitonic
//! merge sort as log2(n)(log2(n)+1)/2 fragment passes over a 2D texture (or
//! the fused sort's fewer, heavier passes with the same result), one
//! binary-search pass that writes each grid cell's first photon, and a gather
//! of the photon records into sorted order.

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture};
use crate::timing::Timings;

use super::compaction::{sort_texture_size, Compaction};
use super::{Grid, PhotonFrames, StageClock};

/// Float addresses are exact below 2^24 (the float mantissa).
pub const FLOAT_ADDRESS_LIMIT: u64 = 1 << 24;

pub use crate::layout::INVALID_KEY;

/// The photon map of build A.
pub struct SortedPhotonMap {
    /// Sorted (cell, record) pairs.
    pub pairs: Texture,
    /// Sorted photon records: position (w = 1 valid), power, incoming direction.
    pub position: Texture,
    pub power: Texture,
    pub incoming: Texture,
    /// First sorted index of each slot (cell, or hash bucket), and one entry past the last.
    pub grid_first: Texture,
    pub grid_width: u32,
    pub grid: Grid,
    /// Photons it holds, where the build counted them (a compacting build;
    /// the sort of every record does not).
    pub stored: Option<u32>,
}

/// `keys` as the sort's RG32I records: (key, record index) a texel.
pub fn key_records(keys: &[i32]) -> Vec<i32> {
    keys.iter()
        .enumerate()
        .flat_map(|(i, &key)| [key, i as i32])
        .collect()
}

/// The order the sort must leave `keys` in: (key, record index) pairs by
/// key, ties broken on the index (plain Rust, for checking it).
pub fn sorted_pairs(keys: &[i32]) -> Vec<(i32, i32)> {
    let mut pairs: Vec<(i32, i32)> = keys
        .iter()
        .enumerate()
        .map(|(i, &k)| (k, i as i32))
        .collect();
    pairs.sort_unstable();
    pairs
}

/// Passes of a bitonic sort of n = 2^k elements: k (k + 1) / 2.
pub fn pass_count(n: u64) -> u32 {
    let k = n.max(2).next_power_of_two().trailing_zeros();
    k * (k + 1) / 2
}

/// One pass of the fused sort (`fused_plan`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SortPass {
    /// One step: stage k, distance j (the faithful pass).
    Step { stage: u64, distance: u64 },
    /// Two steps: distances j and j / 2 of stage k (`bitonic_pair.frag`).
    Pair { stage: u64, distance: u64 },
    /// Every step below SORT_BLOCK of stages first..=last (`bitonic_local.frag`).
    Local { first: u64, last: u64 },
}

/// The fused sort's passes for n = 2^k pairs in a texture `width` wide: one
/// local pass sorting every block of SORT_BLOCK, then for each later stage
/// its long steps two a pass (one alone when their count is odd) and one
/// local pass for its short ones. The faithful passes where the texture is
/// narrower than a block. Each pass's result is the faithful steps' it
/// stands for, so the sorted pairs are the same.
pub fn fused_plan(n: u64, width: u32) -> Vec<SortPass> {
    let block = u64::from(crate::layout::SORT_BLOCK);
    let mut plan = Vec::new();
    if u64::from(width) < block || n < block {
        let mut stage = 2;
        while stage <= n {
            let mut distance = stage / 2;
            while distance >= 1 {
                plan.push(SortPass::Step { stage, distance });
                distance /= 2;
            }
            stage *= 2;
        }
        return plan;
    }
    plan.push(SortPass::Local {
        first: 2,
        last: block,
    });
    let mut stage = 2 * block;
    while stage <= n {
        let mut distance = stage / 2;
        while distance >= block {
            if distance / 2 >= block {
                plan.push(SortPass::Pair { stage, distance });
                distance /= 4;
            } else {
                plan.push(SortPass::Step { stage, distance });
                distance /= 2;
            }
        }
        plan.push(SortPass::Local {
            first: stage,
            last: stage,
        });
        stage *= 2;
    }
    plan
}

pub struct BitonicBuild {
    gpu: Gpu,
    /// The fused sort (`fused_plan`: two long steps a pass, short steps in
    /// registers) instead of one faithful pass a step; the same result.
    fused: bool,
    /// Compact stored records on the GPU before sorting (a HistoPyramid); off
    /// for the paper's way, sorting every record of every frame.
    compact: bool,
    /// Float 1D -> 2D addressing (the paper's); exact below 2^24 only.
    float_addressing: bool,
    compaction: Compaction,
    keys: Program,
    bitonic: Program,
    bitonic_pair: Program,
    bitonic_local: Program,
    search: Program,
    gather: Program,
}

impl BitonicBuild {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        Self::with_addressing(gpu, false)
    }

    /// `float_addressing`: the paper's convert1dto2d in floats (`--faithful`),
    /// which also sorts every record (no compaction).
    pub fn with_addressing(gpu: &Gpu, float_addressing: bool) -> Result<Self> {
        let defines: Vec<(&str, String)> = if float_addressing {
            vec![("FLOAT_ADDRESSING", "1".into())]
        } else {
            vec![]
        };
        let p = |name: &str| Program::fullscreen_with(gpu, name, &defines);
        Ok(Self {
            gpu: gpu.clone(),
            // Off: on llvmpipe the fused passes take as long as the faithful
            // ones (`bench build`; the book), so renders keep the paper's.
            fused: false,
            bitonic_pair: p("photon/bitonic_pair.frag")?,
            bitonic_local: p("photon/bitonic_local.frag")?,
            compact: !float_addressing,
            float_addressing,
            compaction: Compaction::new(gpu, &defines, false)?,
            keys: p("photon/keys.frag")?,
            bitonic: p("photon/bitonic.frag")?,
            search: p("photon/binary_search.frag")?,
            gather: p("photon/gather.frag")?,
        })
    }

    /// The same build with compaction switched on or off (off sorts every
    /// record of every frame, as the paper does).
    pub fn compacting(mut self, compact: bool) -> Self {
        self.compact = compact;
        self
    }

    /// The same build with the fused sort or the faithful passes.
    pub fn fusing(mut self, fused: bool) -> Self {
        self.fused = fused && !self.float_addressing;
        self
    }

    /// Sorts the (key, payload) pairs in `pairs` (RG32I or RGBA32I, width x
    /// height a power of two) by key, then payload. Returns the sorted texture and the passes run.
    pub fn sort(&self, pairs: Texture) -> Result<(Texture, u32)> {
        let (w, h) = (pairs.width, pairs.height);
        let n = w as u64 * h as u64;
        assert!(
            n.is_power_of_two(),
            "bitonic sort needs a power-of-two texel count"
        );
        if self.float_addressing && n > FLOAT_ADDRESS_LIMIT {
            return Err(Error::FloatAddressLimit {
                texels: n,
                limit: FLOAT_ADDRESS_LIMIT,
            });
        }
        // Ping-pong between the input and one more texture: read one, draw the other.
        let other = Texture::new(&self.gpu, w, h, pairs.format)?;
        let textures = [pairs, other];
        let targets = [
            Target::new(&self.gpu, &[&textures[0]])?,
            Target::new(&self.gpu, &[&textures[1]])?,
        ];
        let plan = if self.fused {
            fused_plan(n, w)
        } else {
            fused_plan(n, 1)
        };
        let split = |v: u64| {
            if v < w as u64 {
                [v as i32, 0]
            } else {
                [0, (v / w as u64) as i32]
            }
        };
        let mut current = 0;
        for pass in &plan {
            let (from, to) = (&textures[current], &targets[1 - current]);
            match *pass {
                SortPass::Step { stage, distance } => self
                    .bitonic
                    .bind()
                    .texture("u_pairs", from)
                    .ivec2("u_stage_xy", split(stage))
                    .ivec2("u_distance_xy", split(distance))
                    .int("u_width", w as i32)
                    .draw_fullscreen(to, &DrawState::PLAIN)?,
                SortPass::Pair { stage, distance } => self
                    .bitonic_pair
                    .bind()
                    .texture("u_pairs", from)
                    .ivec2("u_stage_xy", split(stage))
                    .ivec2("u_distance_xy", split(distance))
                    .ivec2("u_half_xy", split(distance / 2))
                    .draw_fullscreen(to, &DrawState::PLAIN)?,
                SortPass::Local { first, last } => self
                    .bitonic_local
                    .bind()
                    .texture("u_pairs", from)
                    .int("u_width", w as i32)
                    .int("u_stage_first", first as i32)
                    .int("u_stage_last", last as i32)
                    .draw_fullscreen(to, &DrawState::PLAIN)?,
            }
            current = 1 - current;
        }
        let passes = plan.len() as u32;
        self.gpu.check("bitonic sort")?;
        drop(targets);
        let [a, b] = textures;
        Ok((if current == 0 { a } else { b }, passes))
    }

    /// For each slot 0..=slots (cells, or hash buckets), its lower bound in the sorted pairs.
    pub fn binary_search(&self, sorted: &Texture, cells: u32) -> Result<(Texture, u32)> {
        let (grid_width, grid_height) = cell_table_size(cells);
        let first = Texture::new(&self.gpu, grid_width, grid_height, TexFormat::Rgba32I)?;
        let target = Target::new(&self.gpu, &[&first])?;
        self.search
            .bind()
            .texture("u_sorted", sorted)
            .int("u_sorted_width", sorted.width as i32)
            .int("u_sorted_count", (sorted.width * sorted.height) as i32)
            .int("u_grid_width", grid_width as i32)
            .int("u_cell_count", cells as i32)
            .draw_fullscreen(&target, &DrawState::PLAIN)?;
        self.gpu.check("binary search")?;
        Ok((first, grid_width))
    }

    /// (cell, record) pairs of the stored records only, packed into the first
    /// slots of a power-of-two texture: HistoPyramid count, reduce, traverse.
    /// Returns the pairs and the number of stored records.
    pub fn compacted_pairs(&self, frames: &PhotonFrames, grid: &Grid) -> Result<(Texture, u32)> {
        let c = self.compaction.pairs(frames, grid, None)?;
        Ok((c.pairs, c.count))
    }

    /// The whole build from traced photon frames, with its stages timed.
    pub fn build(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        timings: &mut Timings,
    ) -> Result<SortedPhotonMap> {
        let query = Query::timer(&self.gpu)?;
        let (pairs, stored) = if self.compact {
            let clock = StageClock::start(&self.gpu, &query);
            let c = self.compaction.pairs(frames, grid, None)?;
            clock.stop(timings, "compact", c.passes as usize);
            (c.pairs, Some(c.count))
        } else {
            let (w, h) = sort_texture_size(frames.record_count() as u64);
            let pairs = Texture::new(&self.gpu, w, h, TexFormat::Rg32I)?;
            let target = Target::new(&self.gpu, &[&pairs])?;
            let clock = StageClock::start(&self.gpu, &query);
            let mut b = self.keys.bind();
            grid.bind(&mut b);
            frames.bind_records(&mut b);
            b.int("u_sort_width", w as i32)
                .draw_fullscreen(&target, &DrawState::PLAIN)?;
            clock.stop(timings, "keys", 1);
            drop(target);
            (pairs, None)
        };
        let clock = StageClock::start(&self.gpu, &query);
        let (sorted, passes) = self.sort(pairs)?;
        clock.stop(timings, "bitonic sort", passes as usize);
        let clock = StageClock::start(&self.gpu, &query);
        let (grid_first, grid_width) = self.binary_search(&sorted, grid.slot_count())?;
        clock.stop(timings, "binary search", 1);

        let clock = StageClock::start(&self.gpu, &query);
        let map = gather_records(
            &self.gpu,
            &self.gather,
            frames,
            (sorted, stored),
            (grid_first, grid_width),
            grid,
        )?;
        clock.stop(timings, "gather", 1);
        Ok(map)
    }
}

/// The cell table's texture: `slots` + 1 entries (the count past the last
/// slot), about square.
pub(crate) fn cell_table_size(slots: u32) -> (u32, u32) {
    let entries = slots as u64 + 1;
    let width = (entries as f64).sqrt().ceil() as u32;
    (width, entries.div_ceil(width as u64) as u32)
}

/// The sorted map from its sorted (slot, record) pairs (with the count
/// stored, where the build counted it) and cell table: the
/// records gathered into sorted order (`photon/gather.frag`), power scaled
/// to the emitted count in use.
pub(crate) fn gather_records(
    gpu: &Gpu,
    gather: &Program,
    frames: &PhotonFrames,
    (sorted, stored): (Texture, Option<u32>),
    (grid_first, grid_width): (Texture, u32),
    grid: &Grid,
) -> Result<SortedPhotonMap> {
    let (w, h) = (sorted.width, sorted.height);
    let t = || Texture::new(gpu, w, h, TexFormat::Rgba32F);
    let (position, power, incoming) = (t()?, t()?, t()?);
    let target = Target::new(gpu, &[&position, &power, &incoming])?;
    gather
        .bind()
        .texture("u_sorted", &sorted)
        .texture("u_position", &frames.position)
        .texture("u_power", &frames.power)
        .texture("u_incoming", &frames.incoming)
        .int("u_sorted_width", w as i32)
        .int("u_record_width", frames.width as i32)
        .float("u_power_scale", frames.power_scale)
        .draw_fullscreen(&target, &DrawState::PLAIN)?;
    gpu.check("gathering sorted photons")?;
    Ok(SortedPhotonMap {
        pairs: sorted,
        position,
        power,
        incoming,
        grid_first,
        grid_width,
        grid: *grid,
        stored,
    })
}
