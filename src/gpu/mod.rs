//! The GPGPU substrate: EGL, GL textures and render targets, GLSL programs,
//! full-screen passes and queries. It knows nothing about photons.
//! Invariant: only this module calls glow.
#![allow(unsafe_code)]

pub mod context;
pub mod pass;
pub mod program;
pub mod query;
pub mod texture;
pub mod vertex;

use std::rc::Rc;

use glow::HasContext;

pub use context::{EglPlatform, GlContext};
pub use pass::Bindings;
pub use program::{Program, ShaderError};
pub use query::{OcclusionQuery, TimerQuery};
pub use texture::{PingPong, Target, TexFormat, Texture};
pub use vertex::VertexBuffer;

#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error("EGL: {0}")]
    Egl(String),
    #[error(transparent)]
    Shader(#[from] ShaderError),
    #[error("GL: {0}")]
    Gl(String),
}

/// The GPU: a GL context plus the objects every pass shares.
#[derive(Clone)]
pub struct Gpu {
    pub ctx: Rc<GlContext>,
    empty_vao: glow::VertexArray,
}

/// What the driver offers, as `photonmap info` prints it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Capabilities {
    pub egl_platform: String,
    pub egl_vendor: String,
    pub egl_version: String,
    pub gl_vendor: String,
    pub gl_renderer: String,
    pub gl_version: String,
    pub glsl_version: String,
    pub context_version: String,
    pub max_texture_size: i32,
    pub max_draw_buffers: i32,
    pub max_color_attachments: i32,
    pub point_size_range: [f32; 2],
    pub stencil_bits: i32,
    pub timer_query_bits: i32,
    pub occlusion_query_bits: i32,
    pub float_render_targets: bool,
}

impl Gpu {
    pub fn new(platform: EglPlatform) -> Result<Self, GpuError> {
        let ctx = GlContext::new(platform)?;
        let empty_vao = unsafe { ctx.gl.create_vertex_array() }.map_err(GpuError::Gl)?;
        unsafe {
            // Rasterised points keep their size from the vertex stage (tiles, routing).
            ctx.gl.enable(glow::PROGRAM_POINT_SIZE);
        }
        Ok(Self {
            ctx: Rc::new(ctx),
            empty_vao,
        })
    }

    pub fn gl(&self) -> &glow::Context {
        &self.ctx.gl
    }

    /// Checks glGetError; a non-zero code means a bug in this program, named by `what`.
    pub fn check(&self, what: &str) -> Result<(), GpuError> {
        let err = unsafe { self.gl().get_error() };
        if err == glow::NO_ERROR {
            Ok(())
        } else {
            Err(GpuError::Gl(format!("{what}: GL error 0x{err:04x}")))
        }
    }

    /// Draws one full-screen triangle (3 vertices from gl_VertexID, no buffers)
    /// into `target` with whatever program and bindings are current.
    pub fn draw_fullscreen(&self, target: &Target) {
        target.bind();
        unsafe {
            self.gl().bind_vertex_array(Some(self.empty_vao));
            self.gl().draw_arrays(glow::TRIANGLES, 0, 3);
        }
    }

    /// Draws a full-screen triangle clipped to the rectangle (x, y, w, h) of
    /// `target`: a pass over one band of a texture (a photon frame).
    pub fn draw_region(&self, target: &Target, x: i32, y: i32, w: i32, h: i32) {
        target.bind();
        unsafe {
            let gl = self.gl();
            gl.viewport(x, y, w, h);
            gl.bind_vertex_array(Some(self.empty_vao));
            gl.draw_arrays(glow::TRIANGLES, 0, 3);
        }
    }

    /// Makes what earlier draws wrote to a texture visible to later draws that
    /// read other texels of it while it is attached (GL 4.5 glTextureBarrier).
    pub fn texture_barrier(&self) {
        // glTextureBarrier takes no arguments and returns nothing: the pointer's
        // own type is its signature.
        match self.ctx.proc_address("glTextureBarrier") {
            Some(f) => f(),
            // Without it, finishing the queue is the conservative equivalent.
            None => self.finish(),
        }
    }

    /// Sets up stencil and depth state for one draw, or turns both tests off.
    pub fn set_stencil_routing(&self, on: bool) {
        unsafe {
            let gl = self.gl();
            if on {
                gl.enable(glow::STENCIL_TEST);
                gl.enable(glow::DEPTH_TEST);
                gl.depth_func(glow::LESS);
                gl.depth_mask(true);
                gl.stencil_mask(0xff);
            } else {
                gl.disable(glow::STENCIL_TEST);
                gl.disable(glow::DEPTH_TEST);
            }
        }
    }

    /// Colour writes on every draw buffer on or off.
    pub fn set_color_writes(&self, on: bool) {
        unsafe { self.gl().color_mask(on, on, on, on) }
    }

    /// Depth test that always passes and writes nothing (stencil-only passes).
    pub fn set_depth_test_always_no_write(&self) {
        unsafe {
            self.gl().depth_func(glow::ALWAYS);
            self.gl().depth_mask(false);
        }
    }

    /// glStencilFunc(func, reference, 0xff) and glStencilOp(sfail, dpfail, dppass).
    pub fn stencil(&self, func: u32, reference: i32, ops: [u32; 3]) {
        unsafe {
            self.gl().stencil_func(func, reference, 0xff);
            self.gl().stencil_op(ops[0], ops[1], ops[2]);
        }
    }

    /// Draws `count` points (positions from gl_VertexID in the vertex program).
    pub fn draw_points(&self, target: &Target, first: i32, count: i32) {
        target.bind();
        unsafe {
            self.gl().bind_vertex_array(Some(self.empty_vao));
            self.gl().draw_arrays(glow::POINTS, first, count);
        }
    }

    /// Draws points into whatever target is bound (for many small draws in a row).
    pub fn draw_points_bound(&self, first: i32, count: i32) {
        unsafe {
            self.gl().bind_vertex_array(Some(self.empty_vao));
            self.gl().draw_arrays(glow::POINTS, first, count);
        }
    }

    /// Additive blending (ONE, ONE) on every draw buffer, for accumulating passes.
    pub fn set_additive_blend(&self, on: bool) {
        unsafe {
            if on {
                self.gl().enable(glow::BLEND);
                self.gl().blend_equation(glow::FUNC_ADD);
                self.gl().blend_func(glow::ONE, glow::ONE);
            } else {
                self.gl().disable(glow::BLEND);
            }
        }
    }

    /// Blocks until every command issued so far has run (for wall-clock timing).
    pub fn finish(&self) {
        unsafe { self.gl().finish() }
    }

    pub fn capabilities(&self) -> Capabilities {
        let gl = self.gl();
        unsafe {
            let mut range = [0f32; 2];
            gl.get_parameter_f32_slice(glow::POINT_SIZE_RANGE, &mut range);
            let ext = gl.supported_extensions();
            let stencil_bits = {
                // The default framebuffer may not exist (surfaceless); ask a real one.
                let probe = Texture::new(self, 1, 1, TexFormat::Rgba32F).ok();
                probe
                    .and_then(|t| Target::with_stencil(self, &[&t]).ok())
                    .map(|t| t.stencil_bits())
                    .unwrap_or(0)
            };
            Capabilities {
                egl_platform: self.ctx.platform_name().to_string(),
                egl_vendor: self.ctx.egl_vendor(),
                egl_version: self.ctx.egl_version(),
                gl_vendor: gl.get_parameter_string(glow::VENDOR),
                gl_renderer: gl.get_parameter_string(glow::RENDERER),
                gl_version: gl.get_parameter_string(glow::VERSION),
                glsl_version: gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION),
                context_version: format!("{}.{} core", self.ctx.version.0, self.ctx.version.1),
                max_texture_size: gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE),
                max_draw_buffers: gl.get_parameter_i32(glow::MAX_DRAW_BUFFERS),
                max_color_attachments: gl.get_parameter_i32(glow::MAX_COLOR_ATTACHMENTS),
                point_size_range: range,
                stencil_bits,
                timer_query_bits: if self.ctx.version >= (3, 3)
                    || ext.contains("GL_ARB_timer_query")
                {
                    self.query_counter_bits(glow::TIME_ELAPSED)
                } else {
                    0
                },
                occlusion_query_bits: self.query_counter_bits(glow::SAMPLES_PASSED),
                float_render_targets: true, // core in GL 3.0+, and we hold a 4.x context
            }
        }
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        // The VAO is shared by clones; free it only with the last one.
        if Rc::strong_count(&self.ctx) == 1 {
            unsafe { self.gl().delete_vertex_array(self.empty_vao) };
        }
    }
}

impl Gpu {
    /// GL_QUERY_COUNTER_BITS of a query target, through glGetQueryiv (glow does not wrap it).
    fn query_counter_bits(&self, target: u32) -> i32 {
        type GetQueryiv = extern "system" fn(u32, u32, *mut i32);
        let Some(f) = self.ctx.proc_address("glGetQueryiv") else {
            return 0;
        };
        // SAFETY: the GL 1.5 signature of glGetQueryiv, on the current context.
        let f: GetQueryiv = unsafe { std::mem::transmute(f) };
        let mut bits = 0;
        f(target, glow::QUERY_COUNTER_BITS, &mut bits);
        bits
    }
}

/// GL_MAX_TEXTURE_SIZE: the largest side of a texture or render target.
pub fn max_texture_size(gpu: &Gpu) -> u32 {
    unsafe { gpu.gl().get_parameter_i32(glow::MAX_TEXTURE_SIZE) as u32 }
}
