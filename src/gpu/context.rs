//! Headless GL 4.5 core contexts: the only place that knows a platform.
//!
//! - EGL device (`EGL_EXT_platform_device`): a GPU driver with no window system.
//! - EGL surfaceless (`EGL_MESA_platform_surfaceless`): Mesa, llvmpipe without a GPU.
//! - OSMesa (`libOSMesa.so.8`, Debian's `libosmesa6`): Mesa's off-screen
//!   library, the same llvmpipe. Mesa 25.1 removed OSMesa; on newer Mesa, EGL
//!   surfaceless is the path, and `auto` never needs OSMesa where EGL works.
//!
//! Every library is loaded at run time. EGL displays are process-wide and
//! initialised once (terminating one under another thread's context breaks
//! it); each `GlContext` owns its own context, current on the creating thread.
//! All work goes to framebuffer objects, so no context needs a real surface.

use std::ffi::{c_void, CStr, CString};
use std::sync::{Arc, OnceLock};

use khronos_egl as egl;

use crate::error::{Error, Result};

/// A GL or platform entry point before it is given its real signature.
pub type VoidFn = unsafe extern "system" fn();

/// Which headless platform to make the GL context on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Platform {
    /// A GPU's EGL device, else EGL surfaceless, else OSMesa.
    #[default]
    Auto,
    /// EGL_EXT_platform_device: a GPU driver's device, no window system.
    EglDevice,
    /// Mesa's EGL surfaceless platform (llvmpipe on machines without a GPU).
    EglSurfaceless,
    /// Mesa's off-screen library, libOSMesa.so.8 (removed in Mesa 25.1).
    Osmesa,
}

impl Platform {
    pub fn name(self) -> &'static str {
        match self {
            Platform::Auto => "auto",
            Platform::EglDevice => "egl-device",
            Platform::EglSurfaceless => "egl-surfaceless",
            Platform::Osmesa => "osmesa",
        }
    }
}

const EGL_HINT: &str = "install Mesa's EGL: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri";
const OSMESA_HINT: &str = "install Mesa's OSMesa: apt-get install libosmesa6 (Mesa 25.1 and later have none: use --platform egl-surfaceless)";

/// An OpenGL 4.x core context, current on the thread that created it.
pub struct GlContext {
    pub gl: glow::Context,
    pub version: (i32, i32),
    backend: Backend,
}

enum Backend {
    Egl(EglContext),
    OsMesa(OsMesaContext),
}

impl GlContext {
    pub fn new(platform: Platform) -> Result<Self> {
        match platform {
            Platform::EglDevice => Self::egl(EglKind::Device, false),
            Platform::EglSurfaceless => Self::egl(EglKind::Surfaceless, false),
            Platform::Osmesa => Self::osmesa(),
            Platform::Auto => Self::egl(EglKind::Device, true)
                .or_else(|_| Self::egl(EglKind::Surfaceless, false))
                .or_else(|egl_error| {
                    Self::osmesa().map_err(|osmesa_error| {
                        Error::Platform(format!(
                            "no headless GL 4.5 platform: {egl_error}; and {osmesa_error}"
                        ))
                    })
                }),
        }
    }

    fn egl(kind: EglKind, gpu_only: bool) -> Result<Self> {
        let display = open_display(kind, gpu_only)?;
        let (context, version) = display.create_context()?;
        let egl = &display.egl;
        let gl = load_gl(|name| {
            egl.get_proc_address(name)
                .map_or(std::ptr::null(), |f| f as *const c_void)
        });
        Ok(Self {
            gl,
            version,
            backend: Backend::Egl(EglContext { display, context }),
        })
    }

    fn osmesa() -> Result<Self> {
        let (context, version) = OsMesaContext::new()?;
        let gl = load_gl(|name| {
            context
                .proc_address(name)
                .map_or(std::ptr::null(), |f| f as *const c_void)
        });
        Ok(Self {
            gl,
            version,
            backend: Backend::OsMesa(context),
        })
    }

    /// A GL entry point by name, for the few calls glow does not wrap.
    pub fn proc_address(&self, name: &str) -> Option<VoidFn> {
        match &self.backend {
            Backend::Egl(c) => c.display.egl.get_proc_address(name).map(|f| f as VoidFn),
            Backend::OsMesa(c) => c.proc_address(name),
        }
    }

    /// The platform this context was made on: egl-device, egl-surfaceless or osmesa.
    pub fn platform_name(&self) -> &'static str {
        match &self.backend {
            Backend::Egl(c) => match c.display.kind {
                EglKind::Device => Platform::EglDevice.name(),
                EglKind::Surfaceless => Platform::EglSurfaceless.name(),
            },
            Backend::OsMesa(_) => Platform::Osmesa.name(),
        }
    }

    pub fn platform_vendor(&self) -> String {
        match &self.backend {
            Backend::Egl(c) => c.display.query(egl::VENDOR),
            Backend::OsMesa(_) => "Mesa (OSMesa)".into(),
        }
    }

    pub fn platform_version(&self) -> String {
        match &self.backend {
            Backend::Egl(c) => format!("EGL {}", c.display.query(egl::VERSION)),
            Backend::OsMesa(c) => format!("OSMesa, {}", c.library),
        }
    }
}

/// glow over a platform's loader; the context must be current.
fn load_gl(loader: impl FnMut(&str) -> *const c_void) -> glow::Context {
    // SAFETY: the platform made its context current on this thread just before,
    // and its loader returns GL entry points of that context, or null.
    unsafe { glow::Context::from_loader_function(loader) }
}

// ---- EGL ---------------------------------------------------------------------

const EGL_PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;
const EGL_PLATFORM_DEVICE_EXT: egl::Enum = 0x313F;
const EGL_CONTEXT_OPENGL_DEBUG: egl::Int = 0x31B0;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum EglKind {
    Device,
    Surfaceless,
}

type EglInstance = egl::DynamicInstance<egl::EGL1_5>;

struct SharedDisplay {
    egl: Arc<EglInstance>,
    display: egl::Display,
    kind: EglKind,
}

// SAFETY: an EGLDisplay handle is a process-wide opaque pointer that EGL itself
// allows every thread to use, and the instance is a table of function pointers.
unsafe impl Send for SharedDisplay {}
unsafe impl Sync for SharedDisplay {}

/// Each display asked for, or why it cannot be had: asked once per process,
/// so that threads making contexts at once neither repeat the device probe
/// nor load and unload libEGL under each other.
type DisplayTable = std::sync::Mutex<
    Vec<(
        (EglKind, bool),
        std::result::Result<Arc<SharedDisplay>, String>,
    )>,
>;

static DISPLAYS: OnceLock<DisplayTable> = OnceLock::new();

/// libEGL, loaded once and never unloaded (Mesa keeps threads of its own).
struct LoadedEgl(std::result::Result<Arc<EglInstance>, String>);
// SAFETY: the instance is a library handle and a table of function pointers
// that EGL allows any thread to call.
unsafe impl Send for LoadedEgl {}
unsafe impl Sync for LoadedEgl {}

static EGL: OnceLock<LoadedEgl> = OnceLock::new();

struct EglContext {
    display: Arc<SharedDisplay>,
    context: egl::Context,
}

impl Drop for EglContext {
    fn drop(&mut self) {
        let (egl, d) = (&self.display.egl, self.display.display);
        // Release only our own context: another Gpu's current on this
        // thread must stay current.
        if egl.get_current_context() == Some(self.context) {
            let _ = egl.make_current(d, None, None, None);
        }
        let _ = egl.destroy_context(d, self.context);
    }
}

fn load_egl() -> Result<Arc<EglInstance>> {
    let loaded = EGL.get_or_init(|| {
        // SAFETY: loading the system libEGL, whose ABI is the Khronos one.
        let loaded = unsafe { EglInstance::load_required() };
        LoadedEgl(
            loaded
                .map(Arc::new)
                .map_err(|e| format!("cannot load libEGL.so.1 ({e}); {EGL_HINT}")),
        )
    });
    loaded.0.clone().map_err(Error::Platform)
}

/// The display of `kind`, opened and initialised once per process.
/// `gpu_only` (auto): refuse a device platform that offers only Mesa's software device.
fn open_display(kind: EglKind, gpu_only: bool) -> Result<Arc<SharedDisplay>> {
    let table = DISPLAYS.get_or_init(Default::default);
    let mut table = table.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, d)) = table.iter().find(|(k, _)| *k == (kind, gpu_only)) {
        return d.clone().map_err(Error::Platform);
    }
    let opened = open_new_display(kind, gpu_only);
    table.push((
        (kind, gpu_only),
        opened.as_ref().map(Arc::clone).map_err(|e| e.to_string()),
    ));
    opened
}

fn open_new_display(kind: EglKind, gpu_only: bool) -> Result<Arc<SharedDisplay>> {
    let egl = load_egl()?;
    let client_ext = egl
        .query_string(None, egl::EXTENSIONS)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = match kind {
        EglKind::Device => "device",
        EglKind::Surfaceless => "surfaceless",
    };
    let display = match kind {
        EglKind::Device => device_display(&egl, &client_ext, gpu_only),
        EglKind::Surfaceless => surfaceless_display(&egl, &client_ext),
    }
    .map_err(|e| {
        Error::Platform(format!(
            "cannot open the EGL {name} display: {e}; {EGL_HINT}"
        ))
    })?;
    egl.initialize(display).map_err(|e| {
        Error::Platform(format!(
            "eglInitialize on the EGL {name} display failed: {e}; {EGL_HINT}"
        ))
    })?;
    Ok(Arc::new(SharedDisplay { egl, display, kind }))
}

fn surfaceless_display(
    egl: &EglInstance,
    client_ext: &str,
) -> std::result::Result<egl::Display, String> {
    if !client_ext.contains("EGL_MESA_platform_surfaceless") {
        return Err("EGL_MESA_platform_surfaceless not offered".into());
    }
    // SAFETY: the surfaceless platform takes EGL_DEFAULT_DISPLAY.
    unsafe {
        egl.get_platform_display(
            EGL_PLATFORM_SURFACELESS_MESA,
            egl::DEFAULT_DISPLAY,
            &[egl::ATTRIB_NONE],
        )
    }
    .map_err(|e| e.to_string())
}

fn device_display(
    egl: &EglInstance,
    client_ext: &str,
    gpu_only: bool,
) -> std::result::Result<egl::Display, String> {
    if !client_ext.contains("EGL_EXT_platform_device") {
        return Err("EGL_EXT_platform_device not offered".into());
    }
    type QueryDevices = unsafe extern "system" fn(i32, *mut *mut c_void, *mut i32) -> u32;
    type QueryDeviceString = unsafe extern "system" fn(*mut c_void, i32) -> *const i8;
    let query = egl
        .get_proc_address("eglQueryDevicesEXT")
        .ok_or("eglQueryDevicesEXT missing")?;
    let query_string = egl.get_proc_address("eglQueryDeviceStringEXT");
    let mut devices = vec![std::ptr::null_mut(); 16];
    let mut n = 0;
    // SAFETY: the EXT_device_enumeration signature, with room for 16 devices.
    let found = unsafe {
        let query = std::mem::transmute::<extern "system" fn(), QueryDevices>(query);
        query(16, devices.as_mut_ptr(), &mut n)
    };
    if found == 0 || n <= 0 {
        return Err("no EGL device".into());
    }
    let devices = &devices[..n as usize];
    let extensions = |d: *mut c_void| -> String {
        let Some(qs) = query_string else {
            return String::new();
        };
        // SAFETY: the EXT_device_query signature on a device EGL listed; EGL
        // returns a NUL-terminated static string or null.
        unsafe {
            let qs = std::mem::transmute::<extern "system" fn(), QueryDeviceString>(qs);
            let s = qs(d, egl::EXTENSIONS);
            if s.is_null() {
                String::new()
            } else {
                CStr::from_ptr(s).to_string_lossy().into_owned()
            }
        }
    };
    // Prefer a device that is not Mesa's software device.
    let chosen = devices
        .iter()
        .copied()
        .find(|&d| !extensions(d).contains("EGL_MESA_device_software"))
        .unwrap_or(devices[0]);
    if gpu_only && extensions(chosen).contains("EGL_MESA_device_software") {
        // Only the software device: the device platform brings nothing surfaceless lacks.
        return Err("only Mesa's software device".into());
    }
    // SAFETY: a device handle from eglQueryDevicesEXT is a valid native display.
    unsafe { egl.get_platform_display(EGL_PLATFORM_DEVICE_EXT, chosen, &[egl::ATTRIB_NONE]) }
        .map_err(|e| e.to_string())
}

impl SharedDisplay {
    fn query(&self, what: egl::Int) -> String {
        self.egl
            .query_string(Some(self.display), what)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    /// A GL 4.x core context, made current with no surface.
    fn create_context(self: &Arc<Self>) -> Result<(egl::Context, (i32, i32))> {
        let egl = &self.egl;
        let name = match self.kind {
            EglKind::Device => "egl-device",
            EglKind::Surfaceless => "egl-surfaceless",
        };
        egl.bind_api(egl::OPENGL_API)
            .map_err(|e| Error::Platform(format!("eglBindAPI(OpenGL) failed: {e}")))?;
        let config = [
            &[
                egl::RENDERABLE_TYPE,
                egl::OPENGL_BIT,
                egl::SURFACE_TYPE,
                0,
                egl::NONE,
            ][..],
            &[egl::RENDERABLE_TYPE, egl::OPENGL_BIT, egl::NONE][..],
        ]
        .iter()
        .find_map(|attribs| {
            egl.choose_first_config(self.display, attribs)
                .ok()
                .flatten()
        })
        .ok_or_else(|| Error::Platform(format!("no EGL config with OpenGL; {EGL_HINT}")))?;
        let debug = std::env::var_os("PHOTONMAP_GL_DEBUG").is_some() as egl::Int;
        let (context, version) = [(4, 6), (4, 5)]
            .iter()
            .find_map(|&(major, minor)| {
                let attribs = [
                    egl::CONTEXT_MAJOR_VERSION,
                    major,
                    egl::CONTEXT_MINOR_VERSION,
                    minor,
                    egl::CONTEXT_OPENGL_PROFILE_MASK,
                    egl::CONTEXT_OPENGL_CORE_PROFILE_BIT,
                    EGL_CONTEXT_OPENGL_DEBUG,
                    debug,
                    egl::NONE,
                ];
                egl.create_context(self.display, config, None, &attribs)
                    .ok()
                    .map(|c| (c, (major, minor)))
            })
            .ok_or_else(|| {
                Error::Platform(format!(
                    "no OpenGL 4.5 core context on the {name} platform; {EGL_HINT}"
                ))
            })?;
        egl.make_current(self.display, None, None, Some(context))
            .map_err(|e| Error::Platform(format!("eglMakeCurrent (no surface) failed: {e}")))?;
        Ok((context, version))
    }
}

// ---- OSMesa ------------------------------------------------------------------

const OSMESA_FORMAT: i32 = 0x22;
const OSMESA_RGBA: i32 = 0x1908; // GL_RGBA
const OSMESA_DEPTH_BITS: i32 = 0x30;
const OSMESA_STENCIL_BITS: i32 = 0x31;
const OSMESA_PROFILE: i32 = 0x33;
const OSMESA_CORE_PROFILE: i32 = 0x34;
const OSMESA_CONTEXT_MAJOR_VERSION: i32 = 0x36;
const OSMESA_CONTEXT_MINOR_VERSION: i32 = 0x37;
const GL_UNSIGNED_BYTE: u32 = 0x1401;

/// The library's file name, or the path in PHOTONMAP_OSMESA_LIBRARY (tests
/// point it at a file that does not exist to see the error).
fn osmesa_library() -> String {
    std::env::var("PHOTONMAP_OSMESA_LIBRARY").unwrap_or_else(|_| "libOSMesa.so.8".into())
}

type CreateContextAttribs = unsafe extern "C" fn(*const i32, *mut c_void) -> *mut c_void;
type MakeCurrent = unsafe extern "C" fn(*mut c_void, *mut c_void, u32, i32, i32) -> u8;
type DestroyContext = unsafe extern "C" fn(*mut c_void);
type GetProcAddress = unsafe extern "C" fn(*const std::ffi::c_char) -> Option<VoidFn>;

struct OsMesaContext {
    /// Kept loaded while the context lives: its functions point into it.
    _library: libloading::Library,
    library: String,
    context: *mut c_void,
    destroy: DestroyContext,
    get_proc_address: GetProcAddress,
    /// The 1 x 1 colour buffer the context is current on (nothing draws to it).
    _buffer: Box<[u8; 4]>,
}

impl OsMesaContext {
    fn new() -> Result<(Self, (i32, i32))> {
        let path = osmesa_library();
        // SAFETY: loading Mesa's libOSMesa, whose initialisers have no preconditions.
        let library = unsafe { libloading::Library::new(&path) }
            .map_err(|e| Error::Platform(format!("cannot load {path} ({e}); {OSMESA_HINT}")))?;
        // SAFETY: each symbol is given its signature from GL/osmesa.h (Mesa 22).
        let (create, make_current, destroy, get_proc_address) = unsafe {
            let symbol = |name: &[u8]| {
                library
                    .get::<VoidFn>(name)
                    .map(|s| *s)
                    .map_err(|e| Error::Platform(format!("{path}: {e}; {OSMESA_HINT}")))
            };
            (
                std::mem::transmute::<VoidFn, CreateContextAttribs>(symbol(
                    b"OSMesaCreateContextAttribs\0",
                )?),
                std::mem::transmute::<VoidFn, MakeCurrent>(symbol(b"OSMesaMakeCurrent\0")?),
                std::mem::transmute::<VoidFn, DestroyContext>(symbol(b"OSMesaDestroyContext\0")?),
                std::mem::transmute::<VoidFn, GetProcAddress>(symbol(b"OSMesaGetProcAddress\0")?),
            )
        };
        let mut buffer = Box::new([0u8; 4]);
        for (major, minor) in [(4, 6), (4, 5)] {
            let attribs = [
                OSMESA_FORMAT,
                OSMESA_RGBA,
                OSMESA_DEPTH_BITS,
                24,
                OSMESA_STENCIL_BITS,
                8,
                OSMESA_PROFILE,
                OSMESA_CORE_PROFILE,
                OSMESA_CONTEXT_MAJOR_VERSION,
                major,
                OSMESA_CONTEXT_MINOR_VERSION,
                minor,
                0,
            ];
            // SAFETY: a zero-terminated attribute list and no share context.
            let context = unsafe { create(attribs.as_ptr(), std::ptr::null_mut()) };
            if context.is_null() {
                continue;
            }
            // SAFETY: the context just made, current on a live 1 x 1 RGBA byte
            // buffer that the returned value keeps (boxed, so it never moves).
            let current = unsafe {
                make_current(context, buffer.as_mut_ptr().cast(), GL_UNSIGNED_BYTE, 1, 1)
            };
            let made = Self {
                _library: library,
                library: path.clone(),
                context,
                destroy,
                get_proc_address,
                _buffer: buffer,
            };
            if current == 0 {
                return Err(Error::Platform(format!(
                    "OSMesaMakeCurrent failed ({path}); {OSMESA_HINT}"
                )));
            }
            return Ok((made, (major, minor)));
        }
        Err(Error::Platform(format!(
            "{path} gives no OpenGL 4.5 core context; {OSMESA_HINT}"
        )))
    }

    fn proc_address(&self, name: &str) -> Option<VoidFn> {
        let name = CString::new(name).ok()?;
        // SAFETY: a NUL-terminated name; OSMesa returns an entry point or null.
        unsafe { (self.get_proc_address)(name.as_ptr()) }
    }
}

impl Drop for OsMesaContext {
    fn drop(&mut self) {
        // SAFETY: the context this value made, destroyed once, while the
        // library that made it is still loaded (fields drop after this).
        unsafe { (self.destroy)(self.context) }
    }
}
