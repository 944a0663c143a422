//! The one error type of the library. Every variant says what went wrong in
//! words a user can act on; the binary adds context with anyhow and nothing else.

use std::path::{Path, PathBuf};

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// A shader that did not compile or link, located in its glsl/ file.
#[derive(Debug, thiserror::Error)]
#[error("glsl/{file}:{line}: {message}\n--- driver log ---\n{log}")]
pub struct ShaderError {
    pub file: String,
    pub line: u32,
    pub message: String,
    pub log: String,
}

/// A scene that could not be loaded: where, which field, and why.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}:{line}: {field}: {message}", file.display())]
pub struct SceneError {
    pub file: PathBuf,
    pub line: usize,
    /// Dotted path of the offending field, e.g. `shape[2].radius`.
    pub field: String,
    pub message: String,
}

impl SceneError {
    pub fn new(file: &Path, line: usize, field: &str, message: String) -> Self {
        SceneError {
            file: file.to_path_buf(),
            line,
            field: field.into(),
            message,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// SIGINT or SIGTERM came (src/interrupt.rs): the work stopped and nothing was written.
    #[error("interrupted by {}: stopped, and no output was written", signal_name(*.signal))]
    Interrupted { signal: i32 },
    /// A signal stopped the work after what was done had been written
    /// (`render --on-signal write-partial`).
    #[error("interrupted by {}: stopped; {wrote}", signal_name(*.signal))]
    InterruptedAfterWriting { signal: i32, wrote: String },
    /// The headless platform (EGL or OSMesa) could not give a GL 4.5 context.
    #[error("{0}")]
    Platform(String),
    #[error(transparent)]
    Shader(#[from] ShaderError),
    /// glGetError after a stage: a bug in this program, named by the stage.
    #[error("GL: {what}: GL error 0x{code:04x}")]
    Gl { what: String, code: u32 },
    /// The driver could not create an object (texture, framebuffer, query...).
    #[error("GL: creating {what}: {message}")]
    Create { what: String, message: String },
    #[error("GL: out of memory creating {resource} ({gib:.1} GiB)")]
    OutOfMemory { resource: String, gib: f64 },
    /// A resource larger than the driver allows; `message` says what to change.
    #[error("GL: {0}")]
    TooLarge(String),
    /// A framebuffer the driver will not draw to.
    #[error("GL: framebuffer incomplete: 0x{0:04x}")]
    IncompleteFramebuffer(u32),
    /// A program compiled for another scene (its kinds of primitive,
    /// material or light, its vertex normals, or a scene uniform block laid
    /// out another way) bound to this scene: a bug in this program.
    #[error("glsl/{0}: compiled for another scene's kinds; compile it after packing this scene")]
    SceneMismatch(String),
    /// A uniform set from Rust that the program does not declare (a misspelled
    /// name would otherwise read 0 and fail silently).
    #[error("glsl/{program}: sets uniform {name}, which the program does not declare")]
    UndeclaredUniform { program: String, name: String },
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error("cannot {action} {}: {source}", path.display())]
    Io {
        action: &'static str,
        path: PathBuf,
        source: std::io::Error,
    },
    /// An image that cannot be encoded or decoded.
    #[error("{0}")]
    Image(String),
    /// Two images that should have one size.
    #[error("image sizes differ: {a_width} x {a_height} and {b_width} x {b_height}")]
    SizeMismatch {
        a_width: u32,
        a_height: u32,
        b_width: u32,
        b_height: u32,
    },
    /// A parameter outside its allowed range, or options that exclude each other.
    #[error("{0}")]
    InvalidOption(String),
    /// An option outside its allowed range, named by its field
    /// (`igi.vpl_paths`); the command line names it by its flag instead.
    #[error("{option} = {value}: {allowed}")]
    OutOfRange {
        option: &'static str,
        value: String,
        allowed: String,
    },
    /// The paper's float addressing refuses what floats cannot address exactly.
    #[error("GL: --faithful float addressing is exact only below 2^24 = {limit} texels; this sort has {texels}: use fewer photons or drop --faithful")]
    FloatAddressLimit { texels: u64, limit: u64 },
    /// Photon tracing stored nothing the map could hold.
    #[error("GL: {emitted} photons emitted and none stored: no diffuse surface is reached after a bounce (photon maps store diffuse hits after the first; add a diffuse surface{remedy})")]
    NoPhotonsStored { emitted: u32, remedy: &'static str },
    #[error("GL: {emitted} photons emitted stored only {stored} of the {target} asked for: the scene's lights reach too few diffuse surfaces after a bounce (lower photons_stored{remedy})")]
    TooFewPhotonsStored {
        emitted: u32,
        stored: u64,
        target: u32,
        remedy: &'static str,
    },
    #[error("GL: the scene stores caustics only, but no light can send a photon towards a mirror or glass shape")]
    NoCausticPath,
}

impl Error {
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            action,
            path: path.into(),
            source,
        }
    }

    /// For `map_err` on a GL object's creation: the driver's `message` on
    /// creating `what`.
    pub fn creating(what: impl Into<String>) -> impl FnOnce(String) -> Self {
        let what = what.into();
        move |message| Error::Create { what, message }
    }

    /// `option` (a field path, `igi.vpl_paths`) is `value`, outside what is
    /// `allowed` (a range, or what to give instead).
    pub fn out_of_range(
        option: &'static str,
        value: impl std::fmt::Display,
        allowed: impl Into<String>,
    ) -> Self {
        Error::OutOfRange {
            option,
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    /// Nothing if `value` is a positive (finite) number; else `option` out
    /// of range, with what to give instead.
    pub fn check_positive(option: &'static str, value: f32, allowed: &str) -> Result<()> {
        if value > 0.0 && value.is_finite() {
            return Ok(());
        }
        Err(Error::out_of_range(option, value, allowed))
    }

    /// Nothing if `range` holds `value`; else `option` out of range, the
    /// allowed range named as `lo..=hi`.
    pub fn check_range<T>(
        option: &'static str,
        value: T,
        range: std::ops::RangeInclusive<T>,
    ) -> Result<()>
    where
        T: PartialOrd + std::fmt::Display,
    {
        if range.contains(&value) {
            return Ok(());
        }
        let allowed = format!("the allowed range is {}..={}", range.start(), range.end());
        Err(Error::out_of_range(option, value, allowed))
    }
}

/// A stopping signal's name, for messages.
pub fn signal_name(signal: i32) -> &'static str {
    match signal {
        2 => "SIGINT",
        15 => "SIGTERM",
        _ => "a signal",
    }
}
