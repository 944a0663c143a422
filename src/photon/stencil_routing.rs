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

use crate::gpu::{
    max_texture_size, Gpu, GpuError, Program, Target, TexFormat, Texture, TimerQuery, VertexBuffer,
};
use crate::render::Timings;

use super::{Grid, PhotonFrames};

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
    /// Photons destined to each cell (x), exact.
    pub counts: Texture,
    pub count_width: u32,
    /// m: a cell's block is m x m slots.
    pub block: u32,
    pub blocks_per_row: u32,
    pub grid: Grid,
}

/// Blocks per row and the routing buffer's size for `cells` cells of m x m.
pub fn routing_layout(cells: u32, block: u32, max_size: u32) -> Result<(u32, u32, u32), GpuError> {
    let per_row = (cells as f64).sqrt().ceil().max(1.0) as u32;
    let rows = cells.div_ceil(per_row);
    let (w, h) = (per_row as u64 * block as u64, rows as u64 * block as u64);
    if w > max_size as u64 || h > max_size as u64 {
        return Err(GpuError::Gl(format!(
            "stencil routing of {cells} cells of {block} x {block} slots needs a {w} x {h} buffer; this driver allows {max_size} a side: use a smaller m or fewer grid cells"
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
}

impl StencilRouting {
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let readback = [("READBACK", "1".to_string())];
        Ok(Self {
            gpu: gpu.clone(),
            pattern: Program::fullscreen(gpu, "photon/stencil_pattern.frag")?,
            route_fetch: Program::new(gpu, "photon/route.vert", "photon/route.frag", &[])?,
            route_readback: Program::new(gpu, "photon/route.vert", "photon/route.frag", &readback)?,
            count_fetch: Program::new(gpu, "photon/route.vert", "photon/count.frag", &[])?,
            count_readback: Program::new(gpu, "photon/route.vert", "photon/count.frag", &readback)?,
            redistribute: Program::fullscreen(gpu, "photon/redistribute.frag")?,
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
    ) -> Result<RoutedPhotonMap, GpuError> {
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
    ) -> Result<(Vec<u8>, RoutedPhotonMap), GpuError> {
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
    ) -> Result<(RoutedPhotonMap, Option<Vec<u8>>), GpuError> {
        if !(1..=16).contains(&block) {
            return Err(GpuError::Gl(format!("stencil routing block m = {block}: the allowed range is 1..=16 (m^2 slots must fit 8 stencil bits)")));
        }
        let cells = grid.cell_count();
        let (per_row, width, height) = routing_layout(cells, block, max_texture_size(&self.gpu))?;
        let t = |w, h| Texture::new(&self.gpu, w, h, TexFormat::Rgba32F);
        let (position, raw_power, incoming) =
            (t(width, height)?, t(width, height)?, t(width, height)?);
        let target = Target::with_stencil(&self.gpu, &[&position, &raw_power, &incoming])?;
        let count_width = (cells as f64).sqrt().ceil() as u32;
        let counts = t(count_width, cells.div_ceil(count_width))?;
        let count_target = Target::new(&self.gpu, &[&counts])?;
        let query = TimerQuery::new(&self.gpu)?;

        // The paper's read-back: photon records to the CPU, back as vertices.
        let vertices = match feed {
            VertexFeed::VertexFetch => None,
            VertexFeed::Readback => {
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
                timings.add("read-back (wall)", wall.elapsed().as_secs_f64(), 1);
                Some(vb)
            }
        };
        let draw = |program: &Program, target: &Target, size: [i32; 2], per_row: u32, m: u32| {
            let mut b = program.bind();
            grid.bind(&mut b);
            b.int("u_record_width", frames.width as i32)
                .int("u_frame_height", frames.frame_height as i32)
                .int("u_photons_used", frames.photons_used as i32)
                .int("u_blocks_per_row", per_row as i32)
                .ivec2("u_target_size", size)
                .int("u_block", m as i32);
            match &vertices {
                Some(vb) => vb.draw_points(target),
                None => {
                    b.texture("u_position", &frames.position)
                        .texture("u_power", &frames.power)
                        .texture("u_incoming", &frames.incoming);
                    self.gpu
                        .draw_points(target, 0, frames.record_count() as i32);
                }
            }
        };

        query.begin();
        target.clear([0.0; 4]);
        target.clear_depth_stencil(1.0, 0);
        // Stencil pattern 0..m^2-1 per block (stencil export; colour untouched).
        self.gpu.set_stencil_routing(true);
        self.gpu.set_color_writes(false);
        self.gpu.set_depth_test_always_no_write();
        self.gpu
            .stencil(glow::ALWAYS, 0, [glow::KEEP, glow::KEEP, glow::REPLACE]);
        self.pattern.bind().int("u_block", block as i32);
        self.gpu.draw_fullscreen(&target);
        self.gpu.set_color_writes(true);
        // Route: write where the stencil is m^2-1 (and the slot was never written), always increment.
        self.gpu.set_stencil_routing(true);
        self.gpu.stencil(
            glow::EQUAL,
            (block * block - 1) as i32,
            [glow::INCR, glow::INCR, glow::INCR],
        );
        let program = if vertices.is_some() {
            &self.route_readback
        } else {
            &self.route_fetch
        };
        draw(
            program,
            &target,
            [width as i32, height as i32],
            per_row,
            block,
        );
        self.gpu.set_stencil_routing(false);
        query.end();
        timings.add("route", query.seconds(), 2);
        let stencil = read_stencil.then(|| target.read_stencil());

        // Count destined photons per cell exactly.
        query.begin();
        count_target.clear([0.0; 4]);
        self.gpu.set_additive_blend(true);
        let program = if vertices.is_some() {
            &self.count_readback
        } else {
            &self.count_fetch
        };
        draw(
            program,
            &count_target,
            [counts.width as i32, counts.height as i32],
            count_width,
            1,
        );
        self.gpu.set_additive_blend(false);
        query.end();
        timings.add("count", query.seconds(), 1);

        // Redistribute power: destined / stored per cell.
        let power = t(width, height)?;
        let power_target = Target::new(&self.gpu, &[&power])?;
        query.begin();
        let mut b = self.redistribute.bind();
        b.texture("u_routed_position", &position)
            .texture("u_routed_power", &raw_power)
            .texture("u_counts", &counts)
            .int("u_block", block as i32)
            .int("u_blocks_per_row", per_row as i32)
            .int("u_count_width", count_width as i32)
            .float("u_power_scale", frames.power_scale);
        self.gpu.draw_fullscreen(&power_target);
        query.end();
        timings.add("redistribute", query.seconds(), 1);
        self.gpu.check("stencil routing")?;
        let map = RoutedPhotonMap {
            position,
            power,
            incoming,
            counts,
            count_width,
            block,
            blocks_per_row: per_row,
            grid: *grid,
        };
        Ok((map, stencil))
    }
}
