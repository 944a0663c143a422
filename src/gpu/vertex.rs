//! Vertex buffers: only for the paper's read-back path, where photon records go
//! through the CPU and come back as vertex attributes.

use glow::HasContext;

use super::{Gpu, GpuError};

/// Interleaved f32 vertex attributes with their vertex array.
pub struct VertexBuffer {
    gpu: Gpu,
    vao: glow::VertexArray,
    vbo: glow::Buffer,
    pub count: usize,
}

impl VertexBuffer {
    /// `components[a]` floats for attribute location a, interleaved per vertex.
    pub fn from_f32(gpu: &Gpu, data: &[f32], components: &[i32]) -> Result<Self, GpuError> {
        let stride: i32 = components.iter().sum();
        assert_eq!(data.len() % stride as usize, 0, "vertex data size");
        let gl = gpu.gl();
        unsafe {
            let vao = gl.create_vertex_array().map_err(GpuError::Gl)?;
            let vbo = gl.create_buffer().map_err(GpuError::Gl)?;
            gl.bind_vertex_array(Some(vao));
            gl.bind_buffer(glow::ARRAY_BUFFER, Some(vbo));
            let bytes =
                std::slice::from_raw_parts(data.as_ptr() as *const u8, std::mem::size_of_val(data));
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

    /// Draws every vertex as a point into `target` with the current program.
    pub fn draw_points(&self, target: &super::Target) {
        target.bind();
        unsafe {
            self.gpu.gl().bind_vertex_array(Some(self.vao));
            self.gpu
                .gl()
                .draw_arrays(glow::POINTS, 0, self.count as i32);
        }
    }
}

impl Drop for VertexBuffer {
    fn drop(&mut self) {
        unsafe {
            self.gpu.gl().delete_vertex_array(self.vao);
            self.gpu.gl().delete_buffer(self.vbo);
        }
    }
}
