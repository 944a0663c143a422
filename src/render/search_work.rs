//! Where the kNN search's steps go: the per-pixel counters that
//! glsl/render/knn_search.frag keeps in its `done` state (photons examined,
//! steps, cells opened), summed, and, when asked, how evenly the steps of each
//! pass fall across the lanes that run side by side (divergence).

/// What the search did, summed over its pixels.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SearchWork {
    /// Loop iterations: a photon examined, a cell opened or skipped, a ring ended.
    pub steps: u64,
    /// Photons whose position was read (candidates or not).
    pub photons_examined: u64,
    /// Cells whose photon count was read.
    pub cells_opened: u64,
    /// Lane use per pass, when profiled.
    pub lanes: Option<LaneUse>,
}

impl SearchWork {
    /// The totals from a read-back `done` state (RGBA32I: done, examined,
    /// steps, opened).
    pub fn from_done(done: &[i32]) -> Self {
        let mut w = SearchWork::default();
        for t in done.chunks_exact(4) {
            w.photons_examined += t[1].max(0) as u64;
            w.steps += t[2].max(0) as u64;
            w.cells_opened += t[3].max(0) as u64;
        }
        w
    }
}

/// Lane use: the steps pixels took in a pass against what their block of
/// lanes paid, the block's slowest pixel's steps times its lanes (a SIMD
/// block runs until its last lane is done). Blocks of 4 x 2 pixels stand for
/// llvmpipe's 8-lane (256-bit) vectors, 8 x 4 for a GPU's 32-lane warp.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct LaneUse {
    /// Steps taken, summed over passes.
    pub steps: u64,
    /// Steps paid in 4 x 2 blocks and 8 x 4 blocks.
    pub paid_8_lanes: u64,
    pub paid_32_lanes: u64,
    /// steps / paid: 1 is no divergence.
    pub use_8_lanes: f64,
    pub use_32_lanes: f64,
    #[serde(skip)]
    last: Vec<i32>,
}

impl LaneUse {
    /// Adds one pass, from the `done` state read after it (RGBA32I, row 0
    /// first, `width` texels a row).
    pub fn add_pass(&mut self, done: &[i32], width: usize) {
        let steps: Vec<i32> = done.chunks_exact(4).map(|t| t[2]).collect();
        if self.last.len() != steps.len() {
            self.last = vec![0; steps.len()];
        }
        let this: Vec<u64> = steps
            .iter()
            .zip(&self.last)
            .map(|(now, before)| (now - before).max(0) as u64)
            .collect();
        self.last = steps;
        let height = this.len() / width.max(1);
        self.steps += this.iter().sum::<u64>();
        self.paid_8_lanes += paid(&this, width, height, 4, 2);
        self.paid_32_lanes += paid(&this, width, height, 8, 4);
        let ratio = |paid: u64| {
            if paid == 0 {
                1.0
            } else {
                self.steps as f64 / paid as f64
            }
        };
        self.use_8_lanes = ratio(self.paid_8_lanes);
        self.use_32_lanes = ratio(self.paid_32_lanes);
    }
}

/// Steps paid by blocks of bw x bh pixels: each block's largest count times
/// its lanes.
fn paid(steps: &[u64], width: usize, height: usize, bw: usize, bh: usize) -> u64 {
    let mut total = 0;
    for by in (0..height).step_by(bh) {
        for bx in (0..width).step_by(bw) {
            let mut most = 0;
            for y in by..(by + bh).min(height) {
                for x in bx..(bx + bw).min(width) {
                    most = most.max(steps[y * width + x]);
                }
            }
            total += most * (bw * bh) as u64;
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_steps_use_every_lane_and_one_slow_pixel_wastes_the_rest() {
        let texels =
            |steps: &[i32]| -> Vec<i32> { steps.iter().flat_map(|&s| [0, 0, s, 0]).collect() };
        let mut even = LaneUse::default();
        even.add_pass(&texels(&[5; 32]), 8);
        assert_eq!(even.use_8_lanes, 1.0);
        assert_eq!(even.use_32_lanes, 1.0);
        let mut one = vec![0; 32];
        one[0] = 8;
        let mut lone = LaneUse::default();
        lone.add_pass(&texels(&one), 8);
        assert_eq!(lone.paid_8_lanes, 64);
        assert_eq!(lone.paid_32_lanes, 256);
        // The second pass counts only its own steps.
        let mut more = one.clone();
        more[0] = 10;
        lone.add_pass(&texels(&more), 8);
        assert_eq!(lone.steps, 10);
        assert_eq!(lone.paid_8_lanes, 64 + 16);
    }
}
