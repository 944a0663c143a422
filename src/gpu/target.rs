//! Render targets (framebuffers over textures, multiple render targets, an
//! optional depth-stencil buffer) and ping-pong pairs of them.

use glow::HasContext;

use super::{DrawState, Error, Gpu, Result, Texture};

/// A framebuffer over one or more textures of equal size (multiple render targets),
/// optionally with a depth-stencil buffer.
pub struct Target {
    gpu: Gpu,
    raw: glow::Framebuffer,
    depth_stencil: Option<glow::Renderbuffer>,
    pub width: u32,
    pub height: u32,
    pub attachments: usize,
}

impl Target {
    pub fn new(gpu: &Gpu, colors: &[&Texture]) -> Result<Self> {
        Self::build(gpu, colors, false, 0)
    }

    /// A target over mip level `level` of one texture.
    pub fn for_level(gpu: &Gpu, color: &Texture, level: u32) -> Result<Self> {
        Self::build(gpu, &[color], false, level)
    }

    pub fn with_stencil(gpu: &Gpu, colors: &[&Texture]) -> Result<Self> {
        Self::build(gpu, colors, true, 0)
    }

    fn build(gpu: &Gpu, colors: &[&Texture], depth_stencil: bool, level: u32) -> Result<Self> {
        assert!(!colors.is_empty(), "a target needs a colour attachment");
        let size_at = |t: &Texture| ((t.width >> level).max(1), (t.height >> level).max(1));
        let (width, height) = size_at(colors[0]);
        assert!(
            colors.iter().all(|t| size_at(t) == (width, height)),
            "all attachments of a target must have one size"
        );
        let gl = gpu.gl();
        // SAFETY: gpu module doc; the framebuffer and renderbuffer are made here
        // over textures of this context, and deleted again if incomplete.
        unsafe {
            let raw = gl
                .create_framebuffer()
                .map_err(Error::creating("a framebuffer"))?;
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(raw));
            let mut bufs = Vec::new();
            for (i, t) in colors.iter().enumerate() {
                let att = glow::COLOR_ATTACHMENT0 + i as u32;
                gl.framebuffer_texture_2d(
                    glow::FRAMEBUFFER,
                    att,
                    glow::TEXTURE_2D,
                    Some(t.raw),
                    level as i32,
                );
                bufs.push(att);
            }
            gl.draw_buffers(&bufs);
            let mut rb = None;
            if depth_stencil {
                let r = gl
                    .create_renderbuffer()
                    .map_err(Error::creating("a depth-stencil buffer"))?;
                gl.bind_renderbuffer(glow::RENDERBUFFER, Some(r));
                gl.renderbuffer_storage(
                    glow::RENDERBUFFER,
                    glow::DEPTH24_STENCIL8,
                    width as i32,
                    height as i32,
                );
                gl.framebuffer_renderbuffer(
                    glow::FRAMEBUFFER,
                    glow::DEPTH_STENCIL_ATTACHMENT,
                    glow::RENDERBUFFER,
                    Some(r),
                );
                rb = Some(r);
            }
            let status = gl.check_framebuffer_status(glow::FRAMEBUFFER);
            if status != glow::FRAMEBUFFER_COMPLETE {
                gl.delete_framebuffer(raw);
                if let Some(r) = rb {
                    gl.delete_renderbuffer(r);
                }
                return Err(Error::IncompleteFramebuffer(status));
            }
            Ok(Self {
                gpu: gpu.clone(),
                raw,
                depth_stencil: rb,
                width,
                height,
                attachments: colors.len(),
            })
        }
    }

    /// Binds the framebuffer with a viewport over all of it.
    pub(crate) fn bind(&self) {
        self.bind_region(0, 0, self.width as i32, self.height as i32);
    }

    /// Binds the framebuffer with the viewport (x, y, w, h).
    pub(crate) fn bind_region(&self, x: i32, y: i32, w: i32, h: i32) {
        // SAFETY: gpu module doc; the framebuffer is this value's own.
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.raw));
            gl.viewport(x, y, w, h);
        }
        self.gpu.scissor_for((self.width, self.height));
    }

    /// Clears every colour attachment to `value`.
    pub fn clear(&self, value: [f32; 4]) {
        // SAFETY: gpu module doc; `i` is an attachment of this framebuffer.
        self.clear_each(|gl, i| unsafe { gl.clear_buffer_f32_slice(glow::COLOR, i, &value) });
    }

    /// Clears every colour attachment, integer textures, to `value`.
    pub fn clear_i32(&self, value: [i32; 4]) {
        // SAFETY: as for `clear`.
        self.clear_each(|gl, i| unsafe { gl.clear_buffer_i32_slice(glow::COLOR, i, &value) });
    }

    /// Binds the target and runs `clear` for each colour attachment.
    fn clear_each(&self, clear: impl Fn(&glow::Context, u32)) {
        self.bind();
        // Colour writes must be on for a clear to write.
        self.gpu.apply(&DrawState::PLAIN);
        for i in 0..self.attachments {
            clear(self.gpu.gl(), i as u32);
        }
    }

    /// Clears depth to `depth` and stencil to `stencil` (a target with_stencil).
    pub fn clear_depth_stencil(&self, depth: f32, stencil: i32) {
        self.bind();
        // SAFETY: gpu module doc.
        unsafe {
            let gl = self.gpu.gl();
            gl.depth_mask(true);
            gl.stencil_mask(0xff);
            gl.clear_buffer_depth_stencil(glow::DEPTH_STENCIL, 0, depth, stencil);
        }
        // The depth write mask changed behind the applied state's back.
        self.gpu.forget_state();
    }

    /// Reads the stencil buffer back (row 0 first), for tests.
    pub fn read_stencil(&self) -> Vec<u8> {
        self.bind();
        let mut out = vec![0u8; (self.width * self.height) as usize];
        // SAFETY: gpu module doc; `out` holds one byte per pixel, packed.
        unsafe {
            let gl = self.gpu.gl();
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 1);
            gl.read_pixels(
                0,
                0,
                self.width as i32,
                self.height as i32,
                glow::STENCIL_INDEX,
                glow::UNSIGNED_BYTE,
                glow::PixelPackData::Slice(Some(&mut out)),
            );
        }
        out
    }

    pub fn stencil_bits(&self) -> i32 {
        if self.depth_stencil.is_none() {
            return 0;
        }
        self.bind();
        // SAFETY: gpu module doc; the framebuffer has a depth-stencil attachment.
        unsafe {
            self.gpu.gl().get_framebuffer_attachment_parameter_i32(
                glow::FRAMEBUFFER,
                glow::DEPTH_STENCIL_ATTACHMENT,
                glow::FRAMEBUFFER_ATTACHMENT_STENCIL_SIZE,
            )
        }
    }
}

impl Drop for Target {
    fn drop(&mut self) {
        // SAFETY: gpu module doc; both objects are this value's own.
        unsafe {
            self.gpu.gl().delete_framebuffer(self.raw);
            if let Some(r) = self.depth_stencil {
                self.gpu.gl().delete_renderbuffer(r);
            }
        }
    }
}

/// Two sets of textures with a target each: a pass reads `current` and writes
/// `next`, then `swap` makes what it wrote current (never sample what you draw to).
pub struct PingPong {
    pub textures: [Vec<Texture>; 2],
    targets: [Target; 2],
    current: usize,
}

impl PingPong {
    pub fn new(gpu: &Gpu, width: u32, height: u32, formats: &[super::TexFormat]) -> Result<Self> {
        let make = || -> Result<Vec<Texture>> {
            formats
                .iter()
                .map(|&f| Texture::new(gpu, width, height, f))
                .collect()
        };
        let textures = [make()?, make()?];
        let targets = [
            Target::new(gpu, &textures[0].iter().collect::<Vec<_>>())?,
            Target::new(gpu, &textures[1].iter().collect::<Vec<_>>())?,
        ];
        Ok(Self {
            textures,
            targets,
            current: 0,
        })
    }

    pub fn current(&self) -> &[Texture] {
        &self.textures[self.current]
    }

    pub fn next_target(&self) -> &Target {
        &self.targets[1 - self.current]
    }

    pub fn current_target(&self) -> &Target {
        &self.targets[self.current]
    }

    pub fn swap(&mut self) {
        self.current = 1 - self.current;
    }

    pub fn current_index(&self) -> usize {
        self.current
    }
}
