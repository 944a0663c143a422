//! Float and integer textures, render targets over them, and ping-pong pairs.

use glow::HasContext;

use super::{Gpu, GpuError};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexFormat {
    Rgba32F,
    Rg32F,
    R32F,
    Rgba32I,
    Rg32I,
}

impl TexFormat {
    pub fn channels(self) -> usize {
        match self {
            TexFormat::Rgba32F | TexFormat::Rgba32I => 4,
            TexFormat::Rg32F | TexFormat::Rg32I => 2,
            TexFormat::R32F => 1,
        }
    }
    fn gl(self) -> (u32, u32, u32) {
        match self {
            TexFormat::Rgba32F => (glow::RGBA32F, glow::RGBA, glow::FLOAT),
            TexFormat::Rg32F => (glow::RG32F, glow::RG, glow::FLOAT),
            TexFormat::R32F => (glow::R32F, glow::RED, glow::FLOAT),
            TexFormat::Rgba32I => (glow::RGBA32I, glow::RGBA_INTEGER, glow::INT),
            TexFormat::Rg32I => (glow::RG32I, glow::RG_INTEGER, glow::INT),
        }
    }
}

/// A 2D texture with nearest filtering, read with texelFetch.
pub struct Texture {
    gpu: Gpu,
    pub raw: glow::Texture,
    pub width: u32,
    pub height: u32,
    pub format: TexFormat,
}

impl Texture {
    pub fn new(gpu: &Gpu, width: u32, height: u32, format: TexFormat) -> Result<Self, GpuError> {
        Self::with_levels(gpu, width, height, format, 1)
    }

    /// A texture with `levels` mip levels (each half the size of the one below).
    pub fn with_levels(
        gpu: &Gpu,
        width: u32,
        height: u32,
        format: TexFormat,
        levels: u32,
    ) -> Result<Self, GpuError> {
        let max = unsafe { gpu.gl().get_parameter_i32(glow::MAX_TEXTURE_SIZE) } as u32;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(GpuError::Gl(format!(
                "texture of {width} x {height} texels: each side must be 1..={max} on this driver"
            )));
        }
        let gl = gpu.gl();
        let raw = unsafe { gl.create_texture() }.map_err(GpuError::Gl)?;
        let (internal, _, _) = format.gl();
        unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(raw));
            gl.tex_storage_2d(
                glow::TEXTURE_2D,
                levels as i32,
                internal,
                width as i32,
                height as i32,
            );
            for (p, v) in [
                (glow::TEXTURE_MIN_FILTER, glow::NEAREST),
                (glow::TEXTURE_MAG_FILTER, glow::NEAREST),
                (glow::TEXTURE_WRAP_S, glow::CLAMP_TO_EDGE),
                (glow::TEXTURE_WRAP_T, glow::CLAMP_TO_EDGE),
            ] {
                gl.tex_parameter_i32(glow::TEXTURE_2D, p, v as i32);
            }
        }
        let err = unsafe { gl.get_error() };
        if err != glow::NO_ERROR {
            unsafe { gl.delete_texture(raw) };
            let bytes = width as u64
                * height as u64
                * format.channels() as u64
                * 4
                * (1 + (levels > 1) as u64 / 3);
            return Err(GpuError::Gl(if err == glow::OUT_OF_MEMORY {
                format!(
                    "out of memory creating a {width} x {height} {format:?} texture ({:.1} GiB)",
                    bytes as f64 / (1u64 << 30) as f64
                )
            } else {
                format!("creating a {width} x {height} {format:?} texture: GL error 0x{err:04x}")
            }));
        }
        Ok(Self {
            gpu: gpu.clone(),
            raw,
            width,
            height,
            format,
        })
    }

    /// A float texture filled from `data` (row 0 first, `channels` floats a texel).
    pub fn from_f32(
        gpu: &Gpu,
        width: u32,
        height: u32,
        format: TexFormat,
        data: &[f32],
    ) -> Result<Self, GpuError> {
        let t = Self::new(gpu, width, height, format)?;
        t.upload_f32(data)?;
        Ok(t)
    }

    /// An RGBA32I texture filled from `data` (4 ints a texel).
    pub fn from_i32(gpu: &Gpu, width: u32, height: u32, data: &[i32]) -> Result<Self, GpuError> {
        Self::from_i32_format(gpu, width, height, TexFormat::Rgba32I, data)
    }

    pub fn from_i32_format(
        gpu: &Gpu,
        width: u32,
        height: u32,
        format: TexFormat,
        data: &[i32],
    ) -> Result<Self, GpuError> {
        let t = Self::new(gpu, width, height, format)?;
        assert!(t.is_integer(), "from_i32 with a float format");
        assert_eq!(
            data.len(),
            t.texel_count() * format.channels(),
            "texture data size"
        );
        let (_, fmt, ty) = t.format.gl();
        unsafe {
            let gl = gpu.gl();
            gl.bind_texture(glow::TEXTURE_2D, Some(t.raw));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
            gl.tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                0,
                0,
                t.width as i32,
                t.height as i32,
                fmt,
                ty,
                glow::PixelUnpackData::Slice(Some(bytes_of(data))),
            );
        }
        gpu.check("uploading an integer texture")?;
        Ok(t)
    }

    /// Restricts which mip levels samplers see (texelFetch's lod counts from `base`).
    pub fn set_level_range(&self, base: u32, max: u32) {
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_BASE_LEVEL, base as i32);
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAX_LEVEL, max as i32);
        }
    }

    /// Reads mip level `level` back (row 0 first) into T, `channels` values a texel.
    fn read_level<T: Copy + Default>(&self, level: u32) -> Vec<T> {
        let (w, h) = ((self.width >> level).max(1), (self.height >> level).max(1));
        let mut out = vec![T::default(); (w * h) as usize * self.format.channels()];
        let (_, fmt, ty) = self.format.gl();
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.pixel_store_i32(glow::PACK_ALIGNMENT, 4);
            gl.get_tex_image(
                glow::TEXTURE_2D,
                level as i32,
                fmt,
                ty,
                glow::PixelPackData::Slice(Some(bytes_of_mut(&mut out))),
            );
        }
        out
    }

    /// Reads the whole texture back (row 0 first) as floats.
    pub fn read_f32(&self) -> Vec<f32> {
        assert!(!self.is_integer(), "read_f32 on an integer texture");
        self.read_level(0)
    }

    /// Reads an integer texture back (row 0 first), `channels` ints a texel.
    pub fn read_i32(&self) -> Vec<i32> {
        assert!(self.is_integer(), "read_i32 on a float texture");
        self.read_level(0)
    }

    /// Reads a mip level of an integer texture (row 0 first).
    pub fn read_i32_texel(&self, level: u32) -> Vec<i32> {
        assert!(self.is_integer(), "read_i32_texel on a float texture");
        self.read_level(level)
    }

    pub fn is_integer(&self) -> bool {
        matches!(self.format, TexFormat::Rgba32I | TexFormat::Rg32I)
    }

    pub fn texel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }

    pub fn upload_f32(&self, data: &[f32]) -> Result<(), GpuError> {
        assert!(!self.is_integer(), "upload_f32 on an integer texture");
        assert_eq!(
            data.len(),
            self.texel_count() * self.format.channels(),
            "texture data size"
        );
        let (_, fmt, ty) = self.format.gl();
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.pixel_store_i32(glow::UNPACK_ALIGNMENT, 4);
            gl.tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                0,
                0,
                self.width as i32,
                self.height as i32,
                fmt,
                ty,
                glow::PixelUnpackData::Slice(Some(bytes_of(data))),
            );
        }
        self.gpu.check("uploading a float texture")
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        unsafe { self.gpu.gl().delete_texture(self.raw) };
    }
}

fn bytes_of<T: Copy>(data: &[T]) -> &[u8] {
    // SAFETY: f32 and i32 are plain old data with no padding.
    unsafe { std::slice::from_raw_parts(data.as_ptr() as *const u8, std::mem::size_of_val(data)) }
}

fn bytes_of_mut<T: Copy>(data: &mut [T]) -> &mut [u8] {
    // SAFETY: as above; every bit pattern is a valid f32 or i32.
    unsafe {
        std::slice::from_raw_parts_mut(data.as_mut_ptr() as *mut u8, std::mem::size_of_val(data))
    }
}

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
    pub fn new(gpu: &Gpu, colors: &[&Texture]) -> Result<Self, GpuError> {
        Self::build(gpu, colors, false, 0)
    }

    /// A target over mip level `level` of one texture.
    pub fn for_level(gpu: &Gpu, color: &Texture, level: u32) -> Result<Self, GpuError> {
        Self::build(gpu, &[color], false, level)
    }

    pub fn with_stencil(gpu: &Gpu, colors: &[&Texture]) -> Result<Self, GpuError> {
        Self::build(gpu, colors, true, 0)
    }

    fn build(
        gpu: &Gpu,
        colors: &[&Texture],
        depth_stencil: bool,
        level: u32,
    ) -> Result<Self, GpuError> {
        assert!(!colors.is_empty(), "a target needs a colour attachment");
        let size_at = |t: &Texture| ((t.width >> level).max(1), (t.height >> level).max(1));
        let (width, height) = size_at(colors[0]);
        assert!(
            colors.iter().all(|t| size_at(t) == (width, height)),
            "all attachments of a target must have one size"
        );
        let gl = gpu.gl();
        let raw = unsafe { gl.create_framebuffer() }.map_err(GpuError::Gl)?;
        let mut rb = None;
        unsafe {
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
            if depth_stencil {
                let r = gl.create_renderbuffer().map_err(GpuError::Gl)?;
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
                return Err(GpuError::Gl(format!(
                    "framebuffer incomplete: 0x{status:04x}"
                )));
            }
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

    pub fn bind(&self) {
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_framebuffer(glow::FRAMEBUFFER, Some(self.raw));
            gl.viewport(0, 0, self.width as i32, self.height as i32);
        }
    }

    /// Clears every colour attachment to `value`.
    pub fn clear(&self, value: [f32; 4]) {
        self.bind();
        unsafe {
            for i in 0..self.attachments {
                self.gpu
                    .gl()
                    .clear_buffer_f32_slice(glow::COLOR, i as u32, &value);
            }
        }
    }

    /// Clears depth to `depth` and stencil to `stencil` (a target with_stencil).
    pub fn clear_depth_stencil(&self, depth: f32, stencil: i32) {
        self.bind();
        unsafe {
            self.gpu.gl().depth_mask(true);
            self.gpu.gl().stencil_mask(0xff);
            self.gpu
                .gl()
                .clear_buffer_depth_stencil(glow::DEPTH_STENCIL, 0, depth, stencil);
        }
    }

    /// Reads the stencil buffer back (row 0 first), for tests.
    pub fn read_stencil(&self) -> Vec<u8> {
        self.bind();
        let mut out = vec![0u8; (self.width * self.height) as usize];
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
        self.bind();
        if self.depth_stencil.is_none() {
            return 0;
        }
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
    pub fn new(
        gpu: &Gpu,
        width: u32,
        height: u32,
        formats: &[TexFormat],
    ) -> Result<Self, GpuError> {
        let make = || -> Result<Vec<Texture>, GpuError> {
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
