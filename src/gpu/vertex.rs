//! Vertex buffers: only for the paper's read-back path, where photon records go
//! through the CPU and come back as vertex attributes.

use glow::HasContext;

use super::{Error, Gpu, Result};

/// Interleaved f32 vertex attributes with their vertex array.
pub struct VertexBuffer {
    gpu: Gpu,
    pub(crate) vao: glow::VertexArray,
    vbo: glow::Buffer,
    pub count: usize,
}

impl VertexBuffer {
    /// `components[a]` floats for attribute location a, interleaved per vertex.
    pub fn from_f32(gpu: &Gpu, data: &[f32], components: &[i32]) -> Result<Self> {
        let stride: i32 = components.iter().sum();
        assert_eq!(data.len() % stride as usize, 0, "vertex data size");
        let gl = gpu.gl();
        // SAFETY: gpu module doc; the buffer is filled from `data`'s own bytes
        // (f32 has no padding) and its attributes lie within each vertex.
        unsafe {
            let vao = gl
                .create_vertex_array()
                .map_err(Error::creating("a vertex array"))?;
            let vbo = gl
                .create_buffer()
                .map_err(Error::creating("a vertex buffer"))?;
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
            let bytes =
                std::slice::from_raw_parts(data.as_ptr().cast::<u8>(), std::mem::size_of_val(data));
            gl.buffer_data_u8_slice(glow::ARRAY_BUFFER, bytes, glow::STATIC_DRAW);
            let mut offset = 0;
            for (location, &n) in components.iter().enumerate() {
                gl.enable_vertex_attrib_array(location as u32);
                gl.vertex_attrib_pointer_f32(
                    location as u32,
                    n,
                    glow::FLOAT,
                    false,
                    stride * 4,
                    offset * 4,
                );
                offset += n;
            }
            gl.bind_vertex_array(None);
            gpu.check("creating a vertex buffer")?;
            Ok(Self {
                gpu: gpu.clone(),
                vao,
                vbo,
                count: data.len() / stride as usize,
            })
        }
    }
}

impl Drop for VertexBuffer {
    fn drop(&mut self) {
        // SAFETY: gpu module doc; both objects are this value's own.
        unsafe {
            self.gpu.gl().delete_vertex_array(self.vao);
            self.gpu.gl().delete_buffer(self.vbo);
        }
    }
}
