//! Build B (section 2.2.2): stencil routing. Each grid cell owns an m x m block
//! of slots. The stencil holds 0..m^2-1 in every block; each photon is drawn as
//! a point of size m over its cell's block; the stencil test passes on
//! EQUAL m^2-1 and every op increments, so the k-th photon of a cell lands in
//! slot m^2-1-k. Where the paper's method breaks, and how this one does not:
//! - the 8-bit stencil saturates at 255, so with m = 16 (m^2 = 256 slots) slot
//!   255 would match again for every later photon and be overwritten: a depth
//!   test (the routed fragment writes depth 0.5 against a clear of 1, test LESS)
//!   keeps a written slot from ever being written again;
//! - the stencil cannot count past 255 destined photons, so a separate pass
//!   counts photons per cell with additive blending into a float texture, and
//!   the power of stored photons is scaled by destined / stored from that count.
//!
//! A hashed grid (section 4.4) routes by bucket: a block is a bucket's, shared
//! by the cells that hash to it. A second count pass (`count cells`) adds each
//! photon, kept or not, at the slot of the first photon its bucket kept of the
//! photon's own cell, so that slot holds the cell's destined count; the
//! redistribution scales each kept photon by destined / kept of its own cell
//! and keeps that factor in power .w. A cell whose bucket filled before any of
//! its photons arrived has no slot to carry its power: that power is lost, and
//! counted (`LostPower`; the book, "The hash grid").

use crate::error::Error;
use crate::gpu::{
    Compare, DrawState, Gpu, Program, Query, Result, StencilOp, StencilTest, Target, TexFormat,
    Texture, VertexBuffer,
};
use crate::timing::Timings;

use super::{Grid, GridStorage, PhotonFrames, StageClock};

/// How photon records reach the vertex stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum VertexFeed {
    /// The paper's way: read the photon textures back to the CPU and draw them
    /// from a vertex buffer.
    Readback,
    /// The vertex program fetches each record from the photon textures by
    /// gl_VertexID: nothing leaves the GPU.
    VertexFetch,
}

/// The photon map of build B.
pub struct RoutedPhotonMap {
    /// Slots of every cell's block: xyz, w = 1 where a photon landed.
    pub position: Texture,
    /// Power after redistribution (and the emitted-count scale).
    pub power: Texture,
    pub incoming: Texture,
    /// Photons destined to each slot (cell, or hash bucket) (x), exact.
    pub counts: Texture,
    /// Hashed grids: photons (x) and raw power (yzw) destined to each cell,
    /// at the texel of the cell's first kept photon (routing buffer's size).
    pub cell_counts: Option<Texture>,
    /// Hashed grids: what the full buckets could not represent.
    pub lost: Option<LostPower>,
    pub count_width: u32,
    /// m: a cell's block is m x m slots.
    pub block: u32,
    pub blocks_per_row: u32,
    pub grid: Grid,
}

/// Photons of cells that got no slot in their (full) bucket, whose power no
/// kept photon can carry; power scaled like the map's (per emitted photon).
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct LostPower {
    pub photons: u64,
    pub power: [f32; 3],
    /// Power of every photon routed (lost or not), for the fraction.
    pub routed_power: [f32; 3],
}

impl LostPower {
    /// The same with power scaled (raw power to the map's).
    pub fn scaled(self, s: f32) -> Self {
        Self {
            power: self.power.map(|c| c * s),
            routed_power: self.routed_power.map(|c| c * s),
            ..self
        }
    }

    /// Lost power over routed power, summed over the channels (0 if none routed).
    pub fn fraction(&self) -> f64 {
        let sum = |v: [f32; 3]| v.iter().map(|&c| c as f64).sum::<f64>();
        let total = sum(self.routed_power);
        if total > 0.0 {
            sum(self.power) / total
        } else {
            0.0
        }
    }
}

/// Blocks per row and the routing buffer's size for `cells` cells of m x m.
pub fn routing_layout(cells: u32, block: u32, max_size: u32) -> Result<(u32, u32, u32)> {
    let per_row = (cells as f64).sqrt().ceil().max(1.0) as u32;
    let rows = cells.div_ceil(per_row);
    let (w, h) = (per_row as u64 * block as u64, rows as u64 * block as u64);
    if w > max_size as u64 || h > max_size as u64 {
        return Err(Error::TooLarge(format!(
            "stencil routing of {cells} cells of {block} x {block} slots needs a {w} x {h} buffer; this driver allows {max_size} a side: use a smaller m, fewer grid cells, or --grid hash (a block per bucket)"
        )));
    }
    Ok((per_row, w as u32, h as u32))
}

pub struct StencilRouting {
    gpu: Gpu,
    pattern: Program,
    route_fetch: Program,
    route_readback: Program,
    count_fetch: Program,
    count_readback: Program,
    redistribute: Program,
    count_cells_fetch: Program,
    count_cells_readback: Program,
    redistribute_hashed: Program,
}

impl StencilRouting {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        let readback = [("READBACK", "1".to_string())];
        Ok(Self {
            gpu: gpu.clone(),
            pattern: Program::fullscreen(gpu, "photon/stencil_pattern.frag")?,
            route_fetch: Program::new(gpu, "photon/route.vert", "photon/route.frag", &[])?,
            route_readback: Program::new(gpu, "photon/route.vert", "photon/route.frag", &readback)?,
            count_fetch: Program::new(gpu, "photon/route.vert", "photon/count.frag", &[])?,
            count_readback: Program::new(gpu, "photon/route.vert", "photon/count.frag", &readback)?,
            redistribute: Program::fullscreen(gpu, "photon/redistribute.frag")?,
            count_cells_fetch: Program::new(
                gpu,
                "photon/route.vert",
                "photon/count_cell.frag",
                &[("CELL_COUNT", "1".into())],
            )?,
            count_cells_readback: Program::new(
                gpu,
                "photon/route.vert",
                "photon/count_cell.frag",
                &[("CELL_COUNT", "1".into()), ("READBACK", "1".into())],
            )?,
            redistribute_hashed: Program::fullscreen_with(
                gpu,
                "photon/redistribute.frag",
                &[("HASHED", "1".into())],
            )?,
        })
    }

    /// Routes the stored photons of `frames` into m x m blocks (m = `block`, 1..=16).
    pub fn build(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        block: u32,
        feed: VertexFeed,
        timings: &mut Timings,
    ) -> Result<RoutedPhotonMap> {
        Ok(self
            .build_inner(frames, grid, block, feed, timings, false)?
            .0)
    }

    /// The build, also returning the stencil buffer after routing (for tests).
    pub fn build_for_stencil_test(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        block: u32,
    ) -> Result<(Vec<u8>, RoutedPhotonMap)> {
        let (map, stencil) = self.build_inner(
            frames,
            grid,
            block,
            VertexFeed::VertexFetch,
            &mut Timings::default(),
            true,
        )?;
        Ok((stencil.unwrap_or_default(), map))
    }

    fn build_inner(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        block: u32,
        feed: VertexFeed,
        timings: &mut Timings,
        read_stencil: bool,
    ) -> Result<(RoutedPhotonMap, Option<Vec<u8>>)> {
        if !(1..=16).contains(&block) {
            return Err(Error::InvalidOption(format!("stencil routing block m = {block}: the allowed range is 1..=16 (m^2 slots must fit 8 stencil bits)")));
        }
        let cells = grid.slot_count();
        let (per_row, width, height) = routing_layout(cells, block, self.gpu.max_texture_size())?;
        let t = |w, h| Texture::new(&self.gpu, w, h, TexFormat::Rgba32F);
        let (position, raw_power, incoming) =
            (t(width, height)?, t(width, height)?, t(width, height)?);
        let target = Target::with_stencil(&self.gpu, &[&position, &raw_power, &incoming])?;
        let count_width = (cells as f64).sqrt().ceil() as u32;
        let counts = t(count_width, cells.div_ceil(count_width))?;
        let count_target = Target::new(&self.gpu, &[&counts])?;
        let query = Query::timer(&self.gpu)?;
        let vertices = match feed {
            VertexFeed::VertexFetch => None,
            VertexFeed::Readback => Some(self.read_back(frames, timings)?),
        };
        let draw = Draw {
            frames,
            grid,
            vertices: vertices.as_ref(),
        };

        let clock = StageClock::start(&self.gpu, &query);
        target.clear([0.0; 4]);
        target.clear_depth_stencil(1.0, 0);
        // Stencil pattern 0..m^2-1 per block (stencil export; colour untouched).
        self.pattern
            .bind()
            .int("u_block", block as i32)
            .draw_fullscreen(&target, &DrawState::stencil_replace(0))?;
        // Route: write where the stencil is m^2-1 (and the slot was never
        // written: depth LESS against the clear), always increment.
        let route = DrawState {
            stencil: StencilTest::On {
                compare: Compare::Equal,
                reference: (block * block - 1) as i32,
                fail: StencilOp::Incr,
                depth_fail: StencilOp::Incr,
                pass: StencilOp::Incr,
            },
            ..DrawState::Z_BUFFER
        };
        let program = match &vertices {
            Some(_) => &self.route_readback,
            None => &self.route_fetch,
        };
        draw.points(program, &target, &route, per_row, block)?;
        clock.stop(timings, "route", 2);
        let stencil = read_stencil.then(|| target.read_stencil());

        // Count destined photons per cell exactly.
        let clock = StageClock::start(&self.gpu, &query);
        count_target.clear([0.0; 4]);
        let program = match &vertices {
            Some(_) => &self.count_readback,
            None => &self.count_fetch,
        };
        draw.points(program, &count_target, &DrawState::ADDITIVE, count_width, 1)?;
        clock.stop(timings, "count", 1);

        let (cell_counts, lost) = match grid.storage {
            GridStorage::Uniform => (None, None),
            GridStorage::Hashed { .. } => {
                let clock = StageClock::start(&self.gpu, &query);
                let (c, lost) = self.count_cells(&draw, &position, (per_row, block))?;
                clock.stop(timings, "count cells", 2);
                (Some(c), Some(lost))
            }
        };

        // Redistribute power: destined / stored per cell.
        let power = t(width, height)?;
        let power_target = Target::new(&self.gpu, &[&power])?;
        let clock = StageClock::start(&self.gpu, &query);
        self.bind_redistribute(grid, cell_counts.as_ref())
            .texture("u_routed_position", &position)
            .texture("u_routed_power", &raw_power)
            .texture("u_counts", &counts)
            .int("u_block", block as i32)
            .int("u_blocks_per_row", per_row as i32)
            .int("u_count_width", count_width as i32)
            .float("u_power_scale", frames.power_scale)
            .draw_fullscreen(&power_target, &DrawState::PLAIN)?;
        clock.stop(timings, "redistribute", 1);
        self.gpu.check("stencil routing")?;
        let map = RoutedPhotonMap {
            position,
            power,
            incoming,
            counts,
            cell_counts,
            lost: lost.map(|l: LostPower| l.scaled(frames.power_scale)),
            count_width,
            block,
            blocks_per_row: per_row,
            grid: *grid,
        };
        Ok((map, stencil))
    }

    /// The redistribution's program, bound with what only a hashed grid reads.
    fn bind_redistribute<'a>(
        &'a self,
        grid: &Grid,
        cell_counts: Option<&'a Texture>,
    ) -> crate::gpu::Bindings<'a> {
        match cell_counts {
            Some(c) => {
                let mut b = self.redistribute_hashed.bind();
                grid.bind(&mut b);
                b.texture("u_cell_counts", c);
                b
            }
            None => self.redistribute.bind(),
        }
    }

    /// Hashed grids: each cell's destined count and power at its first kept
    /// photon's slot, and the split of lost and kept photons (raw power).
    fn count_cells(
        &self,
        draw: &Draw<'_>,
        routed: &Texture,
        (per_row, block): (u32, u32),
    ) -> Result<(Texture, LostPower)> {
        let (w, h) = (routed.width, routed.height);
        let counts = Texture::new(&self.gpu, w, h, TexFormat::Rgba32F)?;
        let split = Texture::new(&self.gpu, 2, 1, TexFormat::Rgba32F)?;
        let program = match draw.vertices {
            Some(_) => &self.count_cells_readback,
            None => &self.count_cells_fetch,
        };
        for (target_texture, split_flag) in [(&counts, 0), (&split, 1)] {
            let target = Target::new(&self.gpu, &[target_texture])?;
            target.clear([0.0; 4]);
            draw.points_with(program, &target, &DrawState::ADDITIVE, 1, 1, &|b| {
                b.texture("u_routed_position", routed)
                    .int("u_route_block", block as i32)
                    .int("u_route_per_row", per_row as i32)
                    .int("u_split", split_flag);
            })?;
        }
        let s = split.read_f32();
        let rgb = |t: usize| [s[4 * t + 1], s[4 * t + 2], s[4 * t + 3]];
        let lost = LostPower {
            photons: s[0] as u64,
            power: rgb(0),
            routed_power: std::array::from_fn(|c| rgb(0)[c] + rgb(1)[c]),
        };
        Ok((counts, lost))
    }

    /// The paper's read-back: photon records to the CPU, back as vertices.
    fn read_back(&self, frames: &PhotonFrames, timings: &mut Timings) -> Result<VertexBuffer> {
        let wall = std::time::Instant::now();
        let (p, w, i) = (
            frames.position.read_f32(),
            frames.power.read_f32(),
            frames.incoming.read_f32(),
        );
        let mut data = Vec::with_capacity(p.len() * 3);
        for k in 0..p.len() / 4 {
            data.extend_from_slice(&p[4 * k..4 * k + 4]);
            data.extend_from_slice(&w[4 * k..4 * k + 4]);
            data.extend_from_slice(&i[4 * k..4 * k + 4]);
        }
        let vb = VertexBuffer::from_f32(&self.gpu, &data, &[4, 4, 4])?;
        timings.add_since("read-back (wall)", 0.0, wall, 1);
        Ok(vb)
    }
}

/// Every photon record drawn as a point, by vertex fetch or from read-back vertices.
struct Draw<'a> {
    frames: &'a PhotonFrames,
    grid: &'a Grid,
    vertices: Option<&'a VertexBuffer>,
}

impl Draw<'_> {
    /// Points of size `m` into blocks laid `per_row` to a row of `target`.
    fn points(
        &self,
        program: &Program,
        target: &Target,
        state: &DrawState,
        per_row: u32,
        m: u32,
    ) -> Result<()> {
        self.points_with(program, target, state, per_row, m, &|_| {})
    }

    /// The same, with more uniforms bound by `extra`.
    fn points_with(
        &self,
        program: &Program,
        target: &Target,
        state: &DrawState,
        per_row: u32,
        m: u32,
        extra: &dyn Fn(&mut crate::gpu::Bindings<'_>),
    ) -> Result<()> {
        let f = self.frames;
        let mut b = program.bind();
        extra(&mut b);
        self.grid.bind(&mut b);
        b.int("u_record_width", f.width as i32)
            .int("u_frame_height", f.frame_height as i32)
            .int("u_photons_used", f.photons_used as i32)
            .int("u_blocks_per_row", per_row as i32)
            .ivec2("u_target_size", [target.width as i32, target.height as i32])
            .int("u_block", m as i32);
        match self.vertices {
            Some(vb) => b.draw_vertices(target, state, vb),
            None => {
                b.texture("u_position", &f.position)
                    .texture("u_power", &f.power)
                    .texture("u_incoming", &f.incoming);
                b.draw_points(target, state, 0, f.record_count() as i32)
            }
        }
    }
}
