//! Uniform buffers: small read-only arrays that every fragment of a pass may
//! read. llvmpipe loads an element once for all lanes where the index is the
//! same in every lane (a loop over a scene's primitives), where a texel
//! fetch always gathers lane by lane.

use glow::HasContext;

use super::{Error, Gpu, Result};

/// A buffer of 16-byte texels (vec4 or ivec4) for a `layout(std140,
/// binding = N) uniform` block.
pub struct UniformBlock {
    gpu: Gpu,
    pub(crate) raw: glow::Buffer,
}

impl UniformBlock {
    /// 32-bit words (floats as their bits, or ints), four a texel, as the
    /// block's array (std140 lays vec4 and ivec4 arrays out tightly);
    /// refused beyond the driver's GL_MAX_UNIFORM_BLOCK_SIZE.
    pub fn from_words(gpu: &Gpu, words: Vec<u32>) -> Result<Self> {
        let gl = gpu.gl();
        let bytes_needed = std::mem::size_of_val(&words[..]);
        let max = gpu.max_uniform_block_bytes();
        if bytes_needed > max {
            return Err(Error::TooLarge(format!(
                "a uniform block of {bytes_needed} bytes: this driver's hold at most {max}"
            )));
        }
        // SAFETY: gpu module doc; the buffer is filled from a byte copy of
        // `words`.
        unsafe {
            let raw = gl
                .create_buffer()
                .map_err(Error::creating("a uniform buffer"))?;
            gl.bind_buffer(glow::UNIFORM_BUFFER, Some(raw));
            let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_ne_bytes()).collect();
            gl.buffer_data_u8_slice(glow::UNIFORM_BUFFER, &bytes, glow::STATIC_DRAW);
            gl.bind_buffer(glow::UNIFORM_BUFFER, None);
            gpu.check("creating a uniform buffer")?;
            Ok(Self {
                gpu: gpu.clone(),
                raw,
            })
        }
    }
}

impl Drop for UniformBlock {
    fn drop(&mut self) {
        // SAFETY: gpu module doc; the buffer is this value's own.
        unsafe { self.gpu.gl().delete_buffer(self.raw) };
    }
}
