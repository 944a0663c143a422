//! The GPGPU substrate: a headless GL context, textures and render targets,
//! GLSL programs, draws with their full fixed-function state, and queries. It
//! knows nothing about photons.
//!
//! Invariant: only this module calls glow or a platform library. The unsafe
//! code here rests on one fact, stated once: a `Gpu` is not `Send` (it holds an
//! `Rc`), its context is made current on the thread that created it, and every
//! GL object it hands out belongs to that context; so each GL call below is
//! made on the right thread, with the context current and objects it owns.
#![allow(unsafe_code)]

pub mod capabilities;
pub mod context;
pub mod pass;
pub mod program;
pub mod query;
pub mod state;
pub mod target;
pub mod texture;
pub mod uniform_block;
pub mod vertex;

use std::cell::Cell;
use std::rc::Rc;

use glow::HasContext;

pub use crate::error::{Error, Result, ShaderError};
pub use capabilities::Capabilities;
pub use context::{GlContext, Platform};
pub use pass::Bindings;
pub use program::Program;
pub use query::Query;
pub use state::{Blend, Compare, DepthTest, DrawState, StencilOp, StencilTest};
pub use target::{PingPong, Target};
pub use texture::{TexFormat, Texel, Texture};
pub use uniform_block::UniformBlock;
pub use vertex::VertexBuffer;

/// The GPU: a GL context plus the objects every pass shares.
#[derive(Clone)]
pub struct Gpu {
    inner: Rc<Shared>,
}

struct Shared {
    ctx: GlContext,
    empty_vao: glow::VertexArray,
    /// The fixed-function state last applied; None when unknown (after a clear).
    state: Cell<Option<DrawState>>,
    texture_barrier: Option<context::VoidFn>,
    max_texture_size: u32,
    /// While set: draws and clears into targets of this size (the image's)
    /// touch only this rectangle (GL scissor), so a crop costs its pixels.
    pixel_window: Cell<Option<PixelWindow>>,
    /// The scissor rectangle last sent (None: scissor test off).
    scissor: Cell<Option<[i32; 4]>>,
    /// Defines every program compiled from now on gets (`set_scene_defines`).
    scene_defines: std::cell::RefCell<Vec<(&'static str, String)>>,
}

/// Which targets are image-shaped, and the part of them to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelWindow {
    /// The image's size: targets of exactly this size are clipped.
    pub size: (u32, u32),
    /// The rectangle drawn, in GL's coordinates (x, y from the bottom, w, h).
    pub rect: [i32; 4],
}

fn gl_compare(c: Compare) -> u32 {
    match c {
        Compare::Always => glow::ALWAYS,
        Compare::Equal => glow::EQUAL,
        Compare::Less => glow::LESS,
    }
}

fn gl_stencil_op(op: StencilOp) -> u32 {
    match op {
        StencilOp::Keep => glow::KEEP,
        StencilOp::Replace => glow::REPLACE,
        StencilOp::Incr => glow::INCR,
    }
}

impl Gpu {
    pub fn new(platform: Platform) -> Result<Self> {
        let ctx = GlContext::new(platform)?;
        // SAFETY: the context was just made current on this thread (module doc).
        let (empty_vao, max_texture_size) = unsafe {
            let vao = ctx
                .gl
                .create_vertex_array()
                .map_err(Error::creating("the empty vertex array"))?;
            // Rasterised points keep their size from the vertex stage (tiles, routing).
            ctx.gl.enable(glow::PROGRAM_POINT_SIZE);
            ctx.gl.stencil_mask(0xff);
            let max = ctx.gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE);
            (vao, max.max(1) as u32)
        };
        let texture_barrier = ctx.proc_address("glTextureBarrier");
        Ok(Self {
            inner: Rc::new(Shared {
                ctx,
                empty_vao,
                state: Cell::new(None),
                texture_barrier,
                max_texture_size,
                pixel_window: Cell::new(None),
                scissor: Cell::new(None),
                scene_defines: std::cell::RefCell::new(Vec::new()),
            }),
        })
    }

    /// Defines that every program compiled from now on gets, after its own:
    /// what the scene last packed allows its shaders to leave out (scene
    /// packing sets them). Programs compiled earlier keep theirs, so each
    /// define must choose between two ways that are both right for every
    /// scene, and differ only in speed.
    pub fn set_scene_defines(&self, defines: Vec<(&'static str, String)>) {
        *self.inner.scene_defines.borrow_mut() = defines;
    }

    pub(crate) fn scene_defines(&self) -> Vec<(&'static str, String)> {
        self.inner.scene_defines.borrow().clone()
    }

    pub(crate) fn gl(&self) -> &glow::Context {
        &self.inner.ctx.gl
    }

    pub(crate) fn context(&self) -> &GlContext {
        &self.inner.ctx
    }

    /// Clips every later draw and clear into image-sized targets to the
    /// window's rectangle, until set to None.
    pub fn set_pixel_window(&self, window: Option<PixelWindow>) {
        self.inner.pixel_window.set(window);
    }

    /// Turns the scissor test on over the pixel window for a target of
    /// `size`, off for any other (called as a target is bound).
    pub(crate) fn scissor_for(&self, size: (u32, u32)) {
        let want = self
            .inner
            .pixel_window
            .get()
            .filter(|w| w.size == size)
            .map(|w| w.rect);
        if want == self.inner.scissor.get() {
            return;
        }
        let gl = self.gl();
        // SAFETY: module doc; state calls take no object.
        unsafe {
            match want {
                Some([x, y, w, h]) => {
                    gl.enable(glow::SCISSOR_TEST);
                    gl.scissor(x, y, w, h);
                }
                None => gl.disable(glow::SCISSOR_TEST),
            }
        }
        self.inner.scissor.set(want);
    }

    /// GL_MAX_TEXTURE_SIZE: the largest side of a texture or render target.
    pub fn max_texture_size(&self) -> u32 {
        self.inner.max_texture_size
    }

    /// GL_MAX_UNIFORM_BLOCK_SIZE, in bytes.
    pub fn max_uniform_block_bytes(&self) -> usize {
        // SAFETY: module doc; a query of a limit.
        unsafe { self.gl().get_parameter_i32(glow::MAX_UNIFORM_BLOCK_SIZE) }.max(0) as usize
    }

    /// Checks glGetError; a non-zero code means a bug in this program, named by `what`.
    pub fn check(&self, what: &str) -> Result<()> {
        // SAFETY: module doc.
        let code = unsafe { self.gl().get_error() };
        if code == glow::NO_ERROR {
            Ok(())
        } else {
            Err(Error::Gl {
                what: what.into(),
                code,
            })
        }
    }

    /// Makes the fixed function do exactly `state` (only what differs from the
    /// state last applied is sent to the driver).
    pub(crate) fn apply(&self, state: &DrawState) {
        let last = self.inner.state.get();
        if last == Some(*state) {
            return;
        }
        let gl = self.gl();
        // SAFETY: module doc; state calls take no object.
        unsafe {
            let c = state.color_writes;
            if last.map(|l| l.color_writes) != Some(c) {
                gl.color_mask(c, c, c, c);
            }
            if last.map(|l| l.blend) != Some(state.blend) {
                match state.blend {
                    Blend::Off => gl.disable(glow::BLEND),
                    Blend::Additive => {
                        gl.enable(glow::BLEND);
                        gl.blend_equation(glow::FUNC_ADD);
                        gl.blend_func(glow::ONE, glow::ONE);
                    }
                }
            }
            if last.map(|l| l.depth) != Some(state.depth) {
                match state.depth {
                    DepthTest::Off => gl.disable(glow::DEPTH_TEST),
                    DepthTest::On { compare, write } => {
                        gl.enable(glow::DEPTH_TEST);
                        gl.depth_func(gl_compare(compare));
                        gl.depth_mask(write);
                    }
                }
            }
            if last.map(|l| l.stencil) != Some(state.stencil) {
                match state.stencil {
                    StencilTest::Off => gl.disable(glow::STENCIL_TEST),
                    StencilTest::On {
                        compare,
                        reference,
                        fail,
                        depth_fail,
                        pass,
                    } => {
                        gl.enable(glow::STENCIL_TEST);
                        gl.stencil_mask(0xff);
                        gl.stencil_func(gl_compare(compare), reference, 0xff);
                        gl.stencil_op(
                            gl_stencil_op(fail),
                            gl_stencil_op(depth_fail),
                            gl_stencil_op(pass),
                        );
                    }
                }
            }
        }
        self.inner.state.set(Some(*state));
    }

    /// Forgets the applied state (a clear changed write masks behind its back).
    pub(crate) fn forget_state(&self) {
        self.inner.state.set(None);
    }

    pub(crate) fn bind_empty_vertex_array(&self) {
        // SAFETY: module doc; the VAO belongs to this context.
        unsafe { self.gl().bind_vertex_array(Some(self.inner.empty_vao)) }
    }

    /// Makes what earlier draws wrote to a texture visible to later draws that
    /// read other texels of it while it is attached (GL 4.5 glTextureBarrier).
    pub fn texture_barrier(&self) {
        match self.inner.texture_barrier {
            // SAFETY: glTextureBarrier takes nothing and returns nothing, which
            // is the pointer's type; the context is current (module doc).
            Some(f) => unsafe { f() },
            // Without it, finishing the queue is the conservative equivalent.
            None => self.finish(),
        }
    }

    /// Makes what earlier draws stored through images (`Bindings::image`)
    /// visible to later draws' texture fetches, image access and
    /// framebuffer writes (glMemoryBarrier).
    pub fn image_barrier(&self) {
        // SAFETY: module doc; the bits are GL constants.
        unsafe {
            self.gl().memory_barrier(
                glow::TEXTURE_FETCH_BARRIER_BIT
                    | glow::SHADER_IMAGE_ACCESS_BARRIER_BIT
                    | glow::FRAMEBUFFER_BARRIER_BIT,
            )
        }
    }

    /// Blocks until every command issued so far has run (for wall-clock timing).
    pub fn finish(&self) {
        // SAFETY: module doc.
        unsafe { self.gl().finish() }
    }
}

impl Drop for Shared {
    fn drop(&mut self) {
        // SAFETY: module doc; the last clone frees the VAO of its own context.
        unsafe { self.ctx.gl.delete_vertex_array(self.empty_vao) };
    }
}
