//! The floor under any pass: full-screen copies of one texture into another,
//! ping-ponged so that each reads what the last wrote. `bench build` sets
//! its sort passes against them, `bench throughput` each stage.

use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};

pub struct CopyPasses {
    textures: [Texture; 2],
    targets: [Target; 2],
    program: Program,
}

impl CopyPasses {
    /// Two `width` x `height` integer textures of `format` (RG32I: a sort's
    /// (key, record) pairs; RGBA32I: 16 bytes, a float record's size).
    pub fn new(gpu: &Gpu, width: u32, height: u32, format: TexFormat) -> Result<Self> {
        let textures = [
            Texture::new(gpu, width, height, format)?,
            Texture::new(gpu, width, height, format)?,
        ];
        let targets = [
            Target::new(gpu, &[&textures[0]])?,
            Target::new(gpu, &[&textures[1]])?,
        ];
        Ok(Self {
            textures,
            targets,
            program: Program::fullscreen(gpu, "bench/copy_pairs.frag")?,
        })
    }

    /// `n` copy passes, not waited for.
    pub fn run(&self, n: usize) -> Result<()> {
        for i in 0..n {
            self.program
                .bind()
                .texture("u_pairs", &self.textures[i % 2])
                .draw_fullscreen(&self.targets[1 - i % 2], &DrawState::PLAIN)?;
        }
        Ok(())
    }
}
