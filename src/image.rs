//! Linear float RGB images, top row first; PNG (sRGB, clamped) and EXR (linear) output.

use std::path::Path;

use crate::error::{Error, Result};

#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    pub width: u32,
    pub height: u32,
    /// Linear RGB, row 0 = top of the picture.
    pub pixels: Vec<[f32; 3]>,
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

impl Image {
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![[0.0; 3]; (width * height) as usize],
        }
    }

    /// From a GL read-back (RGBA, row 0 = bottom) to top-row-first RGB.
    pub fn from_gl_rgba(width: u32, height: u32, rgba: &[f32]) -> Self {
        let mut pixels = Vec::with_capacity((width * height) as usize);
        for row in (0..height).rev() {
            for x in 0..width {
                let i = ((row * width + x) * 4) as usize;
                pixels.push([rgba[i], rgba[i + 1], rgba[i + 2]]);
            }
        }
        Self {
            width,
            height,
            pixels,
        }
    }

    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Adds `other` pixel by pixel (equal sizes).
    pub fn add(&mut self, other: &Image) {
        assert_eq!(
            (self.width, self.height),
            (other.width, other.height),
            "images of one size"
        );
        for (a, p) in self.pixels.iter_mut().zip(&other.pixels) {
            for c in 0..3 {
                a[c] += p[c];
            }
        }
    }

    /// Divides every channel by `n`.
    pub fn divide(&mut self, n: f32) {
        for p in &mut self.pixels {
            for c in p.iter_mut() {
                *c /= n;
            }
        }
    }

    /// The per-pixel mean of equally sized images: summed in order, then one
    /// division (the box filter of a render's eye samples).
    pub fn average(images: &[Image]) -> Image {
        let mut out = images[0].clone();
        for img in &images[1..] {
            out.add(img);
        }
        if images.len() > 1 {
            out.divide(images.len() as f32);
        }
        out
    }

    pub fn mean(&self) -> [f64; 3] {
        let mut s = [0f64; 3];
        for p in &self.pixels {
            for c in 0..3 {
                s[c] += p[c] as f64;
            }
        }
        s.map(|v| v / self.pixels.len().max(1) as f64)
    }

    pub fn has_non_finite(&self) -> bool {
        self.pixels.iter().flatten().any(|v| !v.is_finite())
    }

    /// 8-bit sRGB PNG (values clamped to [0, 1] before the transfer function).
    pub fn png_bytes(&self) -> Result<Vec<u8>> {
        let mut buf = Vec::with_capacity(self.pixels.len() * 3);
        for p in &self.pixels {
            for c in p {
                buf.push((linear_to_srgb(*c) * 255.0 + 0.5) as u8);
            }
        }
        let img = image::RgbImage::from_raw(self.width, self.height, buf)
            .ok_or_else(|| Error::Image("image buffer size mismatch".into()))?;
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png)
            .map_err(|e| Error::Image(format!("encoding a PNG: {e}")))?;
        Ok(out.into_inner())
    }

    /// Linear float RGB OpenEXR, the same orientation as the PNG.
    pub fn exr_bytes(&self) -> Result<Vec<u8>> {
        use exr::prelude::*;
        let w = self.width as usize;
        let layer = Layer::new(
            (w, self.height as usize),
            LayerAttributes::named("rgb"),
            Encoding::SMALL_LOSSLESS,
            SpecificChannels::rgb(|pos: Vec2<usize>| {
                let p = self.pixels[pos.y() * w + pos.x()];
                (p[0], p[1], p[2])
            }),
        );
        let mut out = std::io::Cursor::new(Vec::new());
        exr::image::Image::from_layer(layer)
            .write()
            .to_buffered(&mut out)
            .map_err(|e| crate::error::Error::Image(format!("encoding an EXR: {e}")))?;
        Ok(out.into_inner())
    }

    pub fn read_exr(path: &Path) -> Result<Self> {
        use exr::prelude::*;
        let img = read_first_rgba_layer_from_file(
            path,
            |res, _| {
                (
                    res.width(),
                    res.height(),
                    vec![[0f32; 3]; res.width() * res.height()],
                )
            },
            |(w, _, px): &mut (usize, usize, Vec<[f32; 3]>),
             pos,
             (r, g, b, _a): (f32, f32, f32, f32)| {
                px[pos.y() * *w + pos.x()] = [r, g, b];
            },
        )
        .map_err(|e| {
            crate::error::Error::Image(format!("cannot read EXR {}: {e}", path.display()))
        })?;
        let (w, h, pixels) = img.layer_data.channel_data.pixels;
        Ok(Self {
            width: w as u32,
            height: h as u32,
            pixels,
        })
    }
}

/// Writes `bytes` to `path` all or nothing: a temporary file beside it, then a
/// rename, so a failure never leaves a partial image behind.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path.file_name().ok_or_else(|| {
        Error::io(
            "write",
            path,
            std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file name"),
        )
    })?;
    // Unique per process and call, so concurrent writers never share a temporary.
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(
        ".{}.{}.{n}.partial",
        name.to_string_lossy(),
        std::process::id()
    ));
    if let Err(e) = std::fs::write(&tmp, bytes) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::io("write", path, e));
    }
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        Error::io("write", path, e)
    })
}
