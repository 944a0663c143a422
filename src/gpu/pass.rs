//! Binding a program with its uniforms and input textures for one pass.

use glow::HasContext;

use super::{Program, Texture};

/// The program in use plus the texture units handed out so far.
pub struct Bindings<'a> {
    program: &'a Program,
    gl: &'a glow::Context,
    next_unit: u32,
}

impl Program {
    /// Makes this program current; uniforms and textures are then set on the result.
    pub fn bind(&self) -> Bindings<'_> {
        // SAFETY: program belongs to the current context.
        #[allow(unsafe_code)]
        let gl = unsafe {
            let gl = &self.gpu_ctx().gl;
            gl.use_program(Some(self.raw));
            gl
        };
        Bindings {
            program: self,
            gl,
            next_unit: 0,
        }
    }
}

#[allow(unsafe_code)]
impl Bindings<'_> {
    pub fn texture(&mut self, name: &str, texture: &Texture) -> &mut Self {
        let unit = self.next_unit;
        self.next_unit += 1;
        unsafe {
            self.gl.active_texture(glow::TEXTURE0 + unit);
            self.gl.bind_texture(glow::TEXTURE_2D, Some(texture.raw));
            self.gl
                .uniform_1_i32(self.program.uniform(name).as_ref(), unit as i32);
        }
        self
    }
    pub fn int(&mut self, name: &str, v: i32) -> &mut Self {
        unsafe {
            self.gl
                .uniform_1_i32(self.program.uniform(name).as_ref(), v)
        };
        self
    }
    pub fn uint(&mut self, name: &str, v: u32) -> &mut Self {
        unsafe {
            self.gl
                .uniform_1_u32(self.program.uniform(name).as_ref(), v)
        };
        self
    }
    pub fn float(&mut self, name: &str, v: f32) -> &mut Self {
        unsafe {
            self.gl
                .uniform_1_f32(self.program.uniform(name).as_ref(), v)
        };
        self
    }
    pub fn vec2(&mut self, name: &str, v: [f32; 2]) -> &mut Self {
        unsafe {
            self.gl
                .uniform_2_f32(self.program.uniform(name).as_ref(), v[0], v[1])
        };
        self
    }
    pub fn vec3(&mut self, name: &str, v: [f32; 3]) -> &mut Self {
        unsafe {
            self.gl
                .uniform_3_f32(self.program.uniform(name).as_ref(), v[0], v[1], v[2])
        };
        self
    }
    pub fn ivec3(&mut self, name: &str, v: [i32; 3]) -> &mut Self {
        unsafe {
            self.gl
                .uniform_3_i32(self.program.uniform(name).as_ref(), v[0], v[1], v[2])
        };
        self
    }
    pub fn ivec2(&mut self, name: &str, v: [i32; 2]) -> &mut Self {
        unsafe {
            self.gl
                .uniform_2_i32(self.program.uniform(name).as_ref(), v[0], v[1])
        };
        self
    }
}
