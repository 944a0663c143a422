//! Float and integer textures, read with texelFetch (nearest, no filtering).

use glow::HasContext;

use super::{Error, Gpu, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexFormat {
    Rgba32F,
    Rg32F,
    R32F,
    Rgba32I,
    Rg32I,
    R32I,
}

impl TexFormat {
    pub fn channels(self) -> usize {
        match self {
            TexFormat::Rgba32F | TexFormat::Rgba32I => 4,
            TexFormat::Rg32F | TexFormat::Rg32I => 2,
            TexFormat::R32F | TexFormat::R32I => 1,
        }
    }

    pub fn is_integer(self) -> bool {
        matches!(
            self,
            TexFormat::Rgba32I | TexFormat::Rg32I | TexFormat::R32I
        )
    }

    pub(crate) fn gl(self) -> (u32, u32, u32) {
        match self {
            TexFormat::Rgba32F => (glow::RGBA32F, glow::RGBA, glow::FLOAT),
            TexFormat::Rg32F => (glow::RG32F, glow::RG, glow::FLOAT),
            TexFormat::R32F => (glow::R32F, glow::RED, glow::FLOAT),
            TexFormat::Rgba32I => (glow::RGBA32I, glow::RGBA_INTEGER, glow::INT),
            TexFormat::Rg32I => (glow::RG32I, glow::RG_INTEGER, glow::INT),
            TexFormat::R32I => (glow::R32I, glow::RED_INTEGER, glow::INT),
        }
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for i32 {}
}

/// A channel type that texels are uploaded from and read back into: plain
/// 4-byte values for which every bit pattern is valid (sealed: f32 and i32).
pub trait Texel: sealed::Sealed + Copy + Default {
    /// Whether textures of this channel type are integer textures.
    const INTEGER: bool;
}

impl Texel for f32 {
    const INTEGER: bool = false;
}

impl Texel for i32 {
    const INTEGER: bool = true;
}

fn bytes_of<T: Texel>(data: &[T]) -> &[u8] {
    // SAFETY: T is f32 or i32 (sealed): no padding, 4-byte aligned, any bytes valid.
    unsafe { std::slice::from_raw_parts(data.as_ptr().cast::<u8>(), std::mem::size_of_val(data)) }
}

fn bytes_of_mut<T: Texel>(data: &mut [T]) -> &mut [u8] {
    // SAFETY: as in `bytes_of`; every bit pattern is a valid f32 or i32.
    unsafe {
        std::slice::from_raw_parts_mut(data.as_mut_ptr().cast::<u8>(), std::mem::size_of_val(data))
    }
}

/// A 2D texture with nearest filtering, read with texelFetch.
pub struct Texture {
    gpu: Gpu,
    pub(crate) raw: glow::Texture,
    pub width: u32,
    pub height: u32,
    pub format: TexFormat,
}

impl Texture {
    pub fn new(gpu: &Gpu, width: u32, height: u32, format: TexFormat) -> Result<Self> {
        Self::with_levels(gpu, width, height, format, 1)
    }

    /// A texture with `levels` mip levels (each half the size of the one below).
    pub fn with_levels(
        gpu: &Gpu,
        width: u32,
        height: u32,
        format: TexFormat,
        levels: u32,
    ) -> Result<Self> {
        let max = gpu.max_texture_size();
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::TooLarge(format!(
                "texture of {width} x {height} texels: each side must be 1..={max} on this driver"
            )));
        }
        let gl = gpu.gl();
        let (internal, _, _) = format.gl();
        // SAFETY: gpu module doc; the texture is created, bound and sized here.
        let (raw, code) = unsafe {
            let raw = gl.create_texture().map_err(Error::creating(format!(
                "a {width} x {height} {format:?} texture"
            )))?;
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
            let code = gl.get_error();
            if code != glow::NO_ERROR {
                gl.delete_texture(raw);
            }
            (raw, code)
        };
        if code != glow::NO_ERROR {
            let resource = format!("a {width} x {height} {format:?} texture");
            return Err(if code == glow::OUT_OF_MEMORY {
                let bytes = width as u64
                    * height as u64
                    * format.channels() as u64
                    * 4
                    * (1 + (levels > 1) as u64 / 3);
                Error::OutOfMemory {
                    resource,
                    gib: bytes as f64 / (1u64 << 30) as f64,
                }
            } else {
                Error::Gl {
                    what: format!("creating {resource}"),
                    code,
                }
            });
        }
        Ok(Self {
            gpu: gpu.clone(),
            raw,
            width,
            height,
            format,
        })
    }

    /// A texture filled from `data` (row 0 first, `channels` values a texel;
    /// floats or ints as `format` holds).
    pub fn from_texels<T: Texel>(
        gpu: &Gpu,
        width: u32,
        height: u32,
        format: TexFormat,
        data: &[T],
    ) -> Result<Self> {
        let t = Self::new(gpu, width, height, format)?;
        t.upload(data)?;
        Ok(t)
    }

    /// An RGBA32I texture filled from `data` (4 ints a texel).
    pub fn from_i32(gpu: &Gpu, width: u32, height: u32, data: &[i32]) -> Result<Self> {
        Self::from_texels(gpu, width, height, TexFormat::Rgba32I, data)
    }

    /// Replaces level 0 with `data` (row 0 first, `channels` values a texel).
    pub fn upload<T: Texel>(&self, data: &[T]) -> Result<()> {
        self.upload_region([0, 0, self.width, self.height], data)
    }

    pub fn upload_f32(&self, data: &[f32]) -> Result<()> {
        self.upload(data)
    }

    /// Binds the texture with rows aligned to 4 bytes for a transfer
    /// (`store`: UNPACK_ALIGNMENT to upload, PACK_ALIGNMENT to read back).
    fn bind_aligned(&self, store: u32) -> &glow::Context {
        let gl = self.gpu.gl();
        // SAFETY: gpu module doc; the texture is this value's own.
        unsafe {
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.pixel_store_i32(store, 4);
        }
        gl
    }

    /// Replaces the `[x, y, width, height]` region of level 0 with `data`.
    pub fn upload_region<T: Texel>(&self, region: [u32; 4], data: &[T]) -> Result<()> {
        assert_eq!(T::INTEGER, self.is_integer(), "texel type against format");
        let [x, y, w, h] = region;
        assert!(
            x + w <= self.width && y + h <= self.height,
            "region inside the texture"
        );
        assert_eq!(
            data.len(),
            (w * h) as usize * self.format.channels(),
            "region data size"
        );
        let (_, fmt, ty) = self.format.gl();
        let gl = self.bind_aligned(glow::UNPACK_ALIGNMENT);
        // SAFETY: gpu module doc; `data` holds exactly the region's texels.
        unsafe {
            gl.tex_sub_image_2d(
                glow::TEXTURE_2D,
                0,
                x as i32,
                y as i32,
                w as i32,
                h as i32,
                fmt,
                ty,
                glow::PixelUnpackData::Slice(Some(bytes_of(data))),
            );
        }
        self.gpu.check("uploading a texture region")
    }

    /// Restricts which mip levels samplers see (texelFetch's lod counts from `base`).
    pub fn set_level_range(&self, base: u32, max: u32) {
        // SAFETY: gpu module doc.
        unsafe {
            let gl = self.gpu.gl();
            gl.bind_texture(glow::TEXTURE_2D, Some(self.raw));
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_BASE_LEVEL, base as i32);
            gl.tex_parameter_i32(glow::TEXTURE_2D, glow::TEXTURE_MAX_LEVEL, max as i32);
        }
    }

    /// Reads mip level `level` back (row 0 first), `channels` values a texel.
    pub fn read_level<T: Texel>(&self, level: u32) -> Vec<T> {
        assert_eq!(T::INTEGER, self.is_integer(), "texel type against format");
        let (w, h) = ((self.width >> level).max(1), (self.height >> level).max(1));
        let mut out = vec![T::default(); (w * h) as usize * self.format.channels()];
        let (_, fmt, ty) = self.format.gl();
        let gl = self.bind_aligned(glow::PACK_ALIGNMENT);
        // SAFETY: gpu module doc; `out` has room for every texel of the level.
        unsafe {
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
        self.read_level(0)
    }

    /// Reads an integer texture back (row 0 first), `channels` ints a texel.
    pub fn read_i32(&self) -> Vec<i32> {
        self.read_level(0)
    }

    /// Reads a mip level of an integer texture (row 0 first).
    pub fn read_i32_texel(&self, level: u32) -> Vec<i32> {
        self.read_level(level)
    }

    pub fn is_integer(&self) -> bool {
        self.format.is_integer()
    }

    pub fn texel_count(&self) -> usize {
        self.width as usize * self.height as usize
    }
}

impl Drop for Texture {
    fn drop(&mut self) {
        // SAFETY: gpu module doc; the texture is this value's own.
        unsafe { self.gpu.gl().delete_texture(self.raw) };
    }
}
