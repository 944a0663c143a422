//! Stream compaction of the stored photon records by HistoPyramid (Ziegler,
//! Tevs, Theobalt and Seidel 2006): level 0 marks each record that is a
//! stored photon in the grid, each level above sums 2 x 2 below, and one
//! traversal pass hands output slot i its i-th marked record's (slot,
//! record) pair. Both sorted-map builds, IGI and photon differentials
//! compact this way. In record order (the counting build), level 0 holds
//! record i at its Z-order texel, so the traversal hands records out in
//! index order, and the traversal also counts each pair into its slot's
//! texel of a Z-ordered histogram.

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};

use super::{Grid, PhotonFrames};

/// A 2D texture of n = 2^k texels: width 2^ceil(k/2), height 2^floor(k/2),
/// the shape of every texture the builds sort, compact or count in.
pub fn sort_texture_size(n: u64) -> (u32, u32) {
    let k = n.max(2).next_power_of_two().trailing_zeros();
    (1 << k.div_ceil(2), 1 << (k / 2))
}

/// Mip levels of a HistoPyramid over a `w` x `h` power-of-two base.
pub fn pyramid_levels(w: u32, h: u32) -> u32 {
    32 - w.max(h).leading_zeros()
}

/// The stored records' (slot, record) pairs, packed into the first `count`
/// texels of a power-of-two RG32I texture (the invalid key after them).
pub struct Compacted {
    pub pairs: Texture,
    pub count: u32,
    /// Passes run: the base, each level's reduction, the traversal.
    pub passes: u32,
}

pub struct Compaction {
    gpu: Gpu,
    record_order: bool,
    base: Program,
    reduce: Program,
    traverse: Program,
}

impl Compaction {
    /// `defines` (FLOAT_ADDRESSING) go to every pass; `record_order` adds
    /// RECORD_ORDER.
    pub fn new(gpu: &Gpu, defines: &[(&str, String)], record_order: bool) -> Result<Self> {
        let mut defines = defines.to_vec();
        if record_order {
            defines.push(("RECORD_ORDER", "1".to_string()));
        }
        let p = |name: &str| Program::fullscreen_with(gpu, name, &defines);
        Ok(Self {
            gpu: gpu.clone(),
            record_order,
            base: p("photon/pyramid_base.frag")?,
            reduce: p("photon/pyramid_reduce.frag")?,
            traverse: p("photon/compact.frag")?,
        })
    }

    /// Sums level 0 of a HistoPyramid up to its one-texel top, a pass a
    /// level (`photon/pyramid_reduce.frag`).
    pub fn reduce(&self, pyramid: &Texture, levels: u32) -> Result<()> {
        for level in 1..levels {
            // Samplers see only the level below while this one is drawn.
            pyramid.set_level_range(level - 1, level - 1);
            let target = Target::for_level(&self.gpu, pyramid, level)?;
            self.reduce
                .bind()
                .texture("u_below", pyramid)
                .draw_fullscreen(&target, &DrawState::PLAIN)?;
        }
        pyramid.set_level_range(0, levels - 1);
        Ok(())
    }

    /// The compacted pairs. In record order, `histogram` (an R32I texture of
    /// one texel a slot, in Z order) is zeroed and each pair counted into it;
    /// otherwise there is none.
    pub fn pairs(
        &self,
        frames: &PhotonFrames,
        grid: &Grid,
        histogram: Option<&Texture>,
    ) -> Result<Compacted> {
        assert_eq!(
            histogram.is_some(),
            self.record_order,
            "a histogram is counted exactly in record order"
        );
        let (w, h) = sort_texture_size(frames.record_count() as u64);
        let levels = pyramid_levels(w, h);
        let pyramid = Texture::with_levels(&self.gpu, w, h, TexFormat::Rgba32I, levels)?;
        {
            let target = Target::for_level(&self.gpu, &pyramid, 0)?;
            let mut b = self.base.bind();
            grid.bind(&mut b);
            frames.bind_records(&mut b);
            b.int("u_level_width", w as i32)
                .draw_fullscreen(&target, &DrawState::PLAIN)?;
        }
        self.reduce(&pyramid, levels)?;
        let count = pyramid.read_i32_texel(levels - 1)[0] as u32;
        if let Some(histogram) = histogram {
            Target::for_level(&self.gpu, histogram, 0)?.clear_i32([0; 4]);
        }
        let (cw, ch) = sort_texture_size(count.max(2) as u64);
        let pairs = Texture::new(&self.gpu, cw, ch, TexFormat::Rg32I)?;
        let target = Target::new(&self.gpu, &[&pairs])?;
        let mut b = self.traverse.bind();
        grid.bind(&mut b);
        b.texture("u_pyramid", &pyramid)
            .int("u_top", levels as i32 - 1)
            .texture("u_position", &frames.position)
            .int("u_record_width", frames.width as i32)
            .int("u_out_width", cw as i32)
            .int("u_count", count as i32);
        if let Some(histogram) = histogram {
            b.image_read_write("u_counts", histogram);
        }
        b.draw_fullscreen(&target, &DrawState::PLAIN)?;
        if histogram.is_some() {
            self.gpu.image_barrier();
        }
        self.gpu.check("compacting stored photons")?;
        Ok(Compacted {
            pairs,
            count,
            passes: levels + 1,
        })
    }
}
