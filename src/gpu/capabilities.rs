//! What the driver offers, as `photonmap info` prints it: the platform, GL
//! strings and limits, and a real framebuffer's stencil bits.

use glow::HasContext;

use super::context;
use super::{Gpu, Target, TexFormat, Texture};

/// What the driver offers, as `photonmap info` prints it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Capabilities {
    pub platform: String,
    pub platform_vendor: String,
    pub platform_version: String,
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
    pub fn capabilities(&self) -> Capabilities {
        let gl = self.gl();
        // The default framebuffer may not exist (surfaceless); ask a real one.
        let stencil_bits = Texture::new(self, 1, 1, TexFormat::Rgba32F)
            .ok()
            .and_then(|t| {
                Target::with_stencil(self, &[&t])
                    .ok()
                    .map(|t| t.stencil_bits())
            })
            .unwrap_or(0);
        let ctx = self.context();
        // SAFETY: module doc; these are queries of constants.
        unsafe {
            let mut range = [0f32; 2];
            gl.get_parameter_f32_slice(glow::POINT_SIZE_RANGE, &mut range);
            Capabilities {
                platform: ctx.platform_name().to_string(),
                platform_vendor: ctx.platform_vendor(),
                platform_version: ctx.platform_version(),
                gl_vendor: gl.get_parameter_string(glow::VENDOR),
                gl_renderer: gl.get_parameter_string(glow::RENDERER),
                gl_version: gl.get_parameter_string(glow::VERSION),
                glsl_version: gl.get_parameter_string(glow::SHADING_LANGUAGE_VERSION),
                context_version: format!("{}.{} core", ctx.version.0, ctx.version.1),
                max_texture_size: gl.get_parameter_i32(glow::MAX_TEXTURE_SIZE),
                max_draw_buffers: gl.get_parameter_i32(glow::MAX_DRAW_BUFFERS),
                max_color_attachments: gl.get_parameter_i32(glow::MAX_COLOR_ATTACHMENTS),
                point_size_range: range,
                stencil_bits,
                // Timer queries are core since GL 3.3; every context here is 4.x.
                timer_query_bits: self.query_counter_bits(glow::TIME_ELAPSED),
                occlusion_query_bits: self.query_counter_bits(glow::SAMPLES_PASSED),
                float_render_targets: true, // core in GL 3.0+, and we hold a 4.x context
            }
        }
    }

    /// GL_QUERY_COUNTER_BITS of a query target, through glGetQueryiv (glow does not wrap it).
    fn query_counter_bits(&self, target: u32) -> i32 {
        type GetQueryiv = unsafe extern "system" fn(u32, u32, *mut i32);
        let Some(f) = self.context().proc_address("glGetQueryiv") else {
            return 0;
        };
        // SAFETY: a GL entry point transmuted to its GL 1.5 signature, called
        // on the current context with a valid out pointer.
        unsafe {
            let f: GetQueryiv = std::mem::transmute::<context::VoidFn, GetQueryiv>(f);
            let mut bits = 0;
            f(target, glow::QUERY_COUNTER_BITS, &mut bits);
            bits
        }
    }
}
