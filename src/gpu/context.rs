//! Headless EGL display and GL 4.x core context: the only place that knows EGL.
//!
//! The display is process-wide and initialised once (EGL displays are shared
//! per platform, and terminating one under another thread's context breaks it);
//! each `Gpu` owns its own context, made current on the creating thread.

use std::ffi::c_void;
use std::sync::{Arc, OnceLock};

use khronos_egl as egl;

use super::GpuError;

const EGL_PLATFORM_SURFACELESS_MESA: egl::Enum = 0x31DD;
const EGL_PLATFORM_DEVICE_EXT: egl::Enum = 0x313F;
const EGL_CONTEXT_OPENGL_DEBUG: egl::Int = 0x31B0;

/// Which EGL platform to open the display on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum EglPlatform {
    /// Device platform when a GPU driver offers one, else Mesa surfaceless.
    #[default]
    Auto,
    /// Mesa's surfaceless platform (llvmpipe on machines without a GPU).
    Surfaceless,
    /// EGL_EXT_platform_device: a GPU driver's device, no window system.
    Device,
}

type EglInstance = egl::DynamicInstance<egl::EGL1_5>;

struct SharedDisplay {
    egl: EglInstance,
    display: egl::Display,
    platform_name: &'static str,
}

// SAFETY of Send/Sync: an EGLDisplay handle is a process-wide opaque pointer that
// EGL itself allows every thread to use.
#[allow(unsafe_code)]
unsafe impl Send for SharedDisplay {}
#[allow(unsafe_code)]
unsafe impl Sync for SharedDisplay {}

type DisplayTable = std::sync::Mutex<Vec<(EglPlatform, Arc<SharedDisplay>)>>;

static DISPLAYS: OnceLock<DisplayTable> = OnceLock::new();

const PACKAGE_HINT: &str =
    "install Mesa's EGL: apt-get install libegl1 libegl-mesa0 libgl1-mesa-dri";

fn load_egl() -> Result<EglInstance, GpuError> {
    #[allow(unsafe_code)]
    // SAFETY: loading the system libEGL; its ABI is the Khronos one.
    let loaded = unsafe { EglInstance::load_required() };
    loaded.map_err(|e| GpuError::Egl(format!("cannot load libEGL.so.1 ({e}); {PACKAGE_HINT}")))
}

fn open_display(platform: EglPlatform) -> Result<Arc<SharedDisplay>, GpuError> {
    let table = DISPLAYS.get_or_init(Default::default);
    let mut table = table.lock().unwrap_or_else(|p| p.into_inner());
    if let Some((_, d)) = table.iter().find(|(p, _)| *p == platform) {
        return Ok(d.clone());
    }
    let egl = load_egl()?;
    let client_ext = egl
        .query_string(None, egl::EXTENSIONS)
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();

    let try_device = || -> Result<egl::Display, String> {
        if !client_ext.contains("EGL_EXT_platform_device") {
            return Err("EGL_EXT_platform_device not offered".into());
        }
        let query = egl
            .get_proc_address("eglQueryDevicesEXT")
            .ok_or("eglQueryDevicesEXT missing")?;
        type QueryDevices = extern "system" fn(i32, *mut *mut c_void, *mut i32) -> u32;
        #[allow(unsafe_code)]
        // SAFETY: the EXT_device_enumeration signature.
        let query: QueryDevices = unsafe { std::mem::transmute(query) };
        let mut devices = vec![std::ptr::null_mut(); 16];
        let mut n = 0;
        if query(16, devices.as_mut_ptr(), &mut n) == 0 || n == 0 {
            return Err("no EGL device".into());
        }
        // Prefer a device that is not Mesa's software device.
        let query_string = egl.get_proc_address("eglQueryDeviceStringEXT");
        let mut chosen = devices[0];
        if let Some(qs) = query_string {
            type QueryDeviceString = extern "system" fn(*mut c_void, i32) -> *const i8;
            #[allow(unsafe_code)]
            // SAFETY: the EXT_device_query signature.
            let qs: QueryDeviceString = unsafe { std::mem::transmute(qs) };
            for &d in &devices[..n as usize] {
                let ext = qs(d, egl::EXTENSIONS);
                #[allow(unsafe_code)]
                // SAFETY: EGL returns a NUL-terminated static string or null.
                let ext = if ext.is_null() {
                    String::new()
                } else {
                    unsafe { std::ffi::CStr::from_ptr(ext) }
                        .to_string_lossy()
                        .into_owned()
                };
                if !ext.contains("EGL_MESA_device_software") {
                    chosen = d;
                    break;
                }
            }
            // Only the software device: the device platform brings nothing surfaceless lacks.
            let first_ext = qs(chosen, egl::EXTENSIONS);
            #[allow(unsafe_code)]
            let first_ext = if first_ext.is_null() {
                String::new()
            } else {
                unsafe { std::ffi::CStr::from_ptr(first_ext) }
                    .to_string_lossy()
                    .into_owned()
            };
            if first_ext.contains("EGL_MESA_device_software") && platform == EglPlatform::Auto {
                return Err("only Mesa's software device".into());
            }
        }
        #[allow(unsafe_code)]
        // SAFETY: a device handle from eglQueryDevicesEXT is a valid native display.
        unsafe { egl.get_platform_display(EGL_PLATFORM_DEVICE_EXT, chosen, &[egl::ATTRIB_NONE]) }
            .map_err(|e| e.to_string())
    };
    let try_surfaceless = || -> Result<egl::Display, String> {
        if !client_ext.contains("EGL_MESA_platform_surfaceless") {
            return Err("EGL_MESA_platform_surfaceless not offered".into());
        }
        #[allow(unsafe_code)]
        // SAFETY: the surfaceless platform takes EGL_DEFAULT_DISPLAY.
        unsafe {
            egl.get_platform_display(
                EGL_PLATFORM_SURFACELESS_MESA,
                egl::DEFAULT_DISPLAY,
                &[egl::ATTRIB_NONE],
            )
        }
        .map_err(|e| e.to_string())
    };

    let (display, platform_name) = match platform {
        EglPlatform::Surfaceless => (try_surfaceless(), "surfaceless"),
        EglPlatform::Device => (try_device(), "device"),
        EglPlatform::Auto => match try_device() {
            Ok(d) => (Ok(d), "device"),
            Err(_) => (try_surfaceless(), "surfaceless"),
        },
    };
    let display = display.map_err(|e| {
        GpuError::Egl(format!(
            "cannot open the EGL {platform_name} display: {e}; {PACKAGE_HINT}"
        ))
    })?;
    egl.initialize(display).map_err(|e| {
        GpuError::Egl(format!(
            "eglInitialize on the {platform_name} display failed: {e}; {PACKAGE_HINT}"
        ))
    })?;
    let shared = Arc::new(SharedDisplay {
        egl,
        display,
        platform_name,
    });
    table.push((platform, shared.clone()));
    Ok(shared)
}

/// An OpenGL 4.x core context, current on the thread that created it.
pub struct GlContext {
    shared: Arc<SharedDisplay>,
    context: egl::Context,
    pub gl: glow::Context,
    pub version: (i32, i32),
}

impl GlContext {
    pub fn new(platform: EglPlatform) -> Result<Self, GpuError> {
        let shared = open_display(platform)?;
        let egl = &shared.egl;
        egl.bind_api(egl::OPENGL_API)
            .map_err(|e| GpuError::Egl(format!("eglBindAPI(OpenGL) failed: {e}")))?;
        let config = egl
            .choose_first_config(
                shared.display,
                &[
                    egl::RENDERABLE_TYPE,
                    egl::OPENGL_BIT,
                    egl::SURFACE_TYPE,
                    0,
                    egl::NONE,
                ],
            )
            .ok()
            .flatten()
            .or_else(|| {
                egl.choose_first_config(
                    shared.display,
                    &[egl::RENDERABLE_TYPE, egl::OPENGL_BIT, egl::NONE],
                )
                .ok()
                .flatten()
            })
            .ok_or_else(|| GpuError::Egl(format!("no EGL config with OpenGL; {PACKAGE_HINT}")))?;
        let debug = std::env::var_os("PHOTONMAP_GL_DEBUG").is_some() as egl::Int;
        let mut context = None;
        let mut version = (0, 0);
        for (major, minor) in [(4, 6), (4, 5), (4, 3)] {
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
            if let Ok(c) = egl.create_context(shared.display, config, None, &attribs) {
                context = Some(c);
                version = (major, minor);
                break;
            }
        }
        let context = context.ok_or_else(|| {
            GpuError::Egl(format!(
                "no OpenGL 4.3+ core context on the EGL {} display; {PACKAGE_HINT}",
                shared.platform_name
            ))
        })?;
        egl.make_current(shared.display, None, None, Some(context))
            .map_err(|e| GpuError::Egl(format!("eglMakeCurrent (surfaceless) failed: {e}")))?;
        #[allow(unsafe_code)]
        // SAFETY: the context is current; the loader returns GL entry points or null.
        let gl = unsafe {
            glow::Context::from_loader_function(|name| {
                egl.get_proc_address(name)
                    .map_or(std::ptr::null(), |f| f as *const c_void)
            })
        };
        Ok(Self {
            shared,
            context,
            gl,
            version,
        })
    }

    pub fn egl_vendor(&self) -> String {
        self.shared
            .egl
            .query_string(Some(self.shared.display), egl::VENDOR)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    pub fn egl_version(&self) -> String {
        self.shared
            .egl
            .query_string(Some(self.shared.display), egl::VERSION)
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    }

    /// A GL or EGL entry point by name, for the few calls glow does not wrap.
    pub fn proc_address(&self, name: &str) -> Option<extern "system" fn()> {
        self.shared.egl.get_proc_address(name)
    }

    pub fn platform_name(&self) -> &'static str {
        self.shared.platform_name
    }
}

impl Drop for GlContext {
    fn drop(&mut self) {
        let egl = &self.shared.egl;
        let _ = egl.make_current(self.shared.display, None, None, None);
        let _ = egl.destroy_context(self.shared.display, self.context);
    }
}
