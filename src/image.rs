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

    /// The `w` x `h` pixels from column `x`, row `y` (rows from the top).
    pub fn crop(&self, x: u32, y: u32, w: u32, h: u32) -> Self {
        let mut pixels = Vec::with_capacity((w * h) as usize);
        for row in y..y + h {
            let start = (row * self.width + x) as usize;
            pixels.extend_from_slice(&self.pixels[start..start + w as usize]);
        }
        Self {
            width: w,
            height: h,
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
        srgb8_png(self.width, self.height, buf)
    }

    /// Linear float RGB OpenEXR, the same orientation as the PNG.
    pub fn exr_bytes(&self) -> Result<Vec<u8>> {
        self.exr_bytes_with(&[])
    }

    /// The EXR with text attributes (provenance) in its header.
    pub fn exr_bytes_with(&self, attributes: &[(String, String)]) -> Result<Vec<u8>> {
        self.exr_bytes_placed(attributes, (0, 0), (self.width, self.height))
    }

    /// The EXR of a part of a frame: its data window starts at `origin`
    /// (column, row from the top) of a display window of `frame` pixels.
    pub fn exr_bytes_placed(
        &self,
        attributes: &[(String, String)],
        origin: (u32, u32),
        frame: (u32, u32),
    ) -> Result<Vec<u8>> {
        use exr::prelude::*;
        let w = self.width as usize;
        let mut layer_attributes = LayerAttributes::named("rgb");
        for (k, v) in attributes {
            // EXR text is Latin-1: anything else is left out rather than mangled.
            if let (Some(k), Some(v)) = (Text::new_or_none(k), Text::new_or_none(v)) {
                layer_attributes.other.insert(k, AttributeValue::Text(v));
            }
        }
        layer_attributes.layer_position = Vec2(origin.0 as i32, origin.1 as i32);
        let layer = Layer::new(
            (w, self.height as usize),
            layer_attributes,
            Encoding::SMALL_LOSSLESS,
            SpecificChannels::rgb(|pos: Vec2<usize>| {
                let p = self.pixels[pos.y() * w + pos.x()];
                (p[0], p[1], p[2])
            }),
        );
        let mut image = exr::image::Image::from_layer(layer);
        image.attributes.display_window =
            IntegerBounds::new((0, 0), (frame.0 as usize, frame.1 as usize));
        let mut out = std::io::Cursor::new(Vec::new());
        image
            .write()
            .to_buffered(&mut out)
            .map_err(|e| crate::error::Error::Image(format!("encoding an EXR: {e}")))?;
        Ok(out.into_inner())
    }

    /// Portable float map (PFM): linear RGB as little-endian f32, bottom row first.
    pub fn pfm_bytes(&self) -> Vec<u8> {
        let mut out = format!("PF\n{} {}\n-1.0\n", self.width, self.height).into_bytes();
        for row in (0..self.height).rev() {
            for x in 0..self.width {
                for c in self.get(x, row) {
                    out.extend_from_slice(&c.to_le_bytes());
                }
            }
        }
        out
    }

    /// Text attributes of an EXR's first layer (the provenance of our own files).
    pub fn exr_attributes(path: &Path) -> Result<Vec<(String, String)>> {
        let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| {
            crate::error::Error::Image(format!("cannot read EXR {}: {e}", path.display()))
        })?;
        let mut out = Vec::new();
        if let Some(h) = meta.headers.first() {
            for (k, v) in &h.own_attributes.other {
                if let exr::meta::attribute::AttributeValue::Text(t) = v {
                    out.push((k.to_string(), t.to_string()));
                }
            }
        }
        out.sort();
        Ok(out)
    }

    /// Where an EXR's pixels sit: its data window's origin (column, row from
    /// the top) and its display window's size.
    pub fn exr_placement(path: &Path) -> Result<((i64, i64), (u64, u64))> {
        let meta = exr::meta::MetaData::read_from_file(path, false).map_err(|e| {
            crate::error::Error::Image(format!("cannot read EXR {}: {e}", path.display()))
        })?;
        let h = meta.headers.first().ok_or_else(|| {
            crate::error::Error::Image(format!("EXR {} has no header", path.display()))
        })?;
        let display = h.shared_attributes.display_window;
        let origin = h.own_attributes.layer_position;
        Ok((
            (
                origin.x() as i64 - display.position.x() as i64,
                origin.y() as i64 - display.position.y() as i64,
            ),
            (display.size.x() as u64, display.size.y() as u64),
        ))
    }

    /// An EXR's header text attributes and the provenance among them (as JSON:
    /// a file of an older version may lack fields).
    pub fn exr_provenance(
        path: &Path,
    ) -> crate::error::Result<(Vec<(String, String)>, serde_json::Value)> {
        let attributes = Self::exr_attributes(path)?;
        let text = attributes
            .iter()
            .find(|(k, _)| k == "photonmap.provenance")
            .map(|(_, v)| v)
            .ok_or_else(|| {
                crate::error::Error::Image(format!(
                    "{}: no photonmap.provenance in its header: not a photonmap render",
                    path.display()
                ))
            })?;
        let provenance = serde_json::from_str(text).map_err(|e| {
            crate::error::Error::Image(format!(
                "{}: its photonmap.provenance is not JSON: {e}",
                path.display()
            ))
        })?;
        Ok((attributes, provenance))
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

/// A PNG of 8-bit sRGB pixels, three bytes each, top row first.
pub fn srgb8_png(width: u32, height: u32, rgb: Vec<u8>) -> Result<Vec<u8>> {
    let img = image::RgbImage::from_raw(width, height, rgb)
        .ok_or_else(|| Error::Image("image buffer size mismatch".into()))?;
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .map_err(|e| Error::Image(format!("encoding a PNG: {e}")))?;
    Ok(out.into_inner())
}

/// Writes `bytes` to `path` all or nothing (see `write_all_atomically`).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomically(&[(path, bytes)])
}

/// Writes every file all or nothing: each into a temporary file beside it
/// (so the rename stays on one file system), flushed to disk; only when every
/// one is written are they renamed into place. A failure on the way (a full
/// disk, a folder that vanished) removes the temporaries: no file appears and
/// the files there before stay as they were.
pub fn write_all_atomically(files: &[(&Path, &[u8])]) -> Result<()> {
    write_all_with(files, &|file, bytes| {
        use std::io::Write;
        file.write_all(bytes)?;
        file.sync_all()
    })
}

/// `write_all_atomically` with the write itself given (tests make it fail).
pub fn write_all_with(
    files: &[(&Path, &[u8])],
    write: &dyn Fn(&mut std::fs::File, &[u8]) -> std::io::Result<()>,
) -> Result<()> {
    let mut temporaries = Vec::with_capacity(files.len());
    for &(path, bytes) in files {
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
        let prefix = format!(".{}.", name.to_string_lossy());
        let mut builder = tempfile::Builder::new();
        builder.prefix(&prefix).suffix(".partial");
        // A temporary file is made 0600, and its mode survives the rename;
        // an output takes what `File::create` gives, 0666 less the umask.
        #[cfg(unix)]
        builder.permissions(std::os::unix::fs::PermissionsExt::from_mode(0o666));
        let mut tmp = builder
            .tempfile_in(dir)
            .map_err(|e| Error::io("write", path, e))?;
        // On an error the temporaries made so far drop here, and delete themselves.
        write(tmp.as_file_mut(), bytes).map_err(|e| Error::io("write", path, e))?;
        temporaries.push((tmp, path));
    }
    for (tmp, path) in temporaries {
        tmp.persist(path)
            .map_err(|e| Error::io("write", path, e.error))?;
    }
    Ok(())
}

/// Whether a file can be made at `path`: its folder exists and takes a new
/// file (checked by making and removing a temporary there), before any work.
pub fn check_writable(path: &Path) -> Result<()> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if path.is_dir() {
        return Err(Error::io(
            "write",
            path,
            std::io::Error::new(std::io::ErrorKind::IsADirectory, "a folder is there"),
        ));
    }
    tempfile::Builder::new()
        .prefix(".photonmap-check.")
        .tempfile_in(dir)
        .map(drop)
        .map_err(|e| Error::io("write", path, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A write that fails halfway (as a full disk does) leaves no file and no
    /// temporary, and the file there before intact; every file or none.
    #[test]
    fn a_failing_write_leaves_nothing_and_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.png"), dir.path().join("b.exr"));
        std::fs::write(&b, b"before").unwrap();
        let full_disk = |file: &mut std::fs::File, bytes: &[u8]| {
            use std::io::Write;
            file.write_all(&bytes[..bytes.len() / 2])?;
            Err(std::io::Error::from_raw_os_error(28)) // ENOSPC
        };
        let err = write_all_with(&[(&a, b"0123456789"), (&b, b"after")], &full_disk).unwrap_err();
        assert!(err.to_string().contains("No space left"), "{err}");
        assert!(!a.exists());
        assert_eq!(std::fs::read(&b).unwrap(), b"before");
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .flatten()
            .map(|e| e.file_name())
            .collect();
        assert_eq!(left.len(), 1, "{left:?}");
        // And when every write works, every file appears.
        write_all_atomically(&[(&a, b"0123456789"), (&b, b"after")]).unwrap();
        assert_eq!(std::fs::read(&b).unwrap(), b"after");
        assert!(a.exists());
    }
}
