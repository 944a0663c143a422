//! One pass: a program made current, its uniforms and input textures, and the
//! draw into a target with its full fixed-function state.

use glow::HasContext;

use super::{DrawState, Error, Program, Result, Target, Texture, VertexBuffer};

/// The program in use plus the texture units handed out so far. A uniform the
/// program does not declare is remembered and makes the next draw fail.
pub struct Bindings<'a> {
    program: &'a Program,
    gl: &'a glow::Context,
    next_unit: u32,
    next_image: u32,
    error: Option<Error>,
}

impl Program {
    /// Makes this program current; uniforms and textures are then set on the
    /// result, and the result draws.
    pub fn bind(&self) -> Bindings<'_> {
        let gl = self.gpu().gl();
        // SAFETY: gpu module doc; the program is this value's own.
        unsafe { gl.use_program(Some(self.raw)) };
        Bindings {
            program: self,
            gl,
            next_unit: 0,
            next_image: 0,
            error: None,
        }
    }
}

impl Bindings<'_> {
    /// Sets uniform `name` through `set` if the program declares it.
    fn set(
        &mut self,
        name: &str,
        set: impl FnOnce(&glow::Context, Option<&glow::UniformLocation>),
    ) -> &mut Self {
        match self.program.uniform(name) {
            Ok(location) => set(self.gl, location.as_ref()),
            Err(e) => {
                self.error.get_or_insert(e);
            }
        }
        self
    }

    pub fn texture(&mut self, name: &str, texture: &Texture) -> &mut Self {
        let unit = self.next_unit;
        self.next_unit += 1;
        // SAFETY: gpu module doc; the program is current and the location, if
        // any, is its own.
        self.set(name, |gl, l| unsafe {
            gl.active_texture(glow::TEXTURE0 + unit);
            gl.bind_texture(glow::TEXTURE_2D, Some(texture.raw));
            gl.uniform_1_i32(l, unit as i32);
        })
    }

    /// Binds level 0 of `texture` as image `name`, for `imageStore` (the
    /// shader declares its format). What a draw stores is visible to later
    /// draws after `Gpu::image_barrier`.
    pub fn image(&mut self, name: &str, texture: &Texture) -> &mut Self {
        self.image_with_access(name, texture, glow::WRITE_ONLY)
    }

    /// Binds level 0 of `texture` as image `name` for reading and writing
    /// (`imageLoad`, `imageAtomic*`).
    pub fn image_read_write(&mut self, name: &str, texture: &Texture) -> &mut Self {
        self.image_with_access(name, texture, glow::READ_WRITE)
    }

    fn image_with_access(&mut self, name: &str, texture: &Texture, access: u32) -> &mut Self {
        let unit = self.next_image;
        self.next_image += 1;
        let format = texture.format.gl().0;
        // SAFETY: as for `texture`; the texture is immutable-format storage
        // of `format`.
        self.set(name, |gl, l| unsafe {
            gl.bind_image_texture(unit, Some(texture.raw), 0, false, 0, access, format);
            gl.uniform_1_i32(l, unit as i32);
        })
    }

    /// Binds `block` to uniform-block binding point `binding` (the
    /// `layout(binding = ...)` its GLSL declaration names).
    pub fn uniform_block(&mut self, binding: u32, block: &super::UniformBlock) -> &mut Self {
        // SAFETY: gpu module doc; the buffer is the block's own.
        unsafe {
            self.gl
                .bind_buffer_base(glow::UNIFORM_BUFFER, binding, Some(block.raw))
        };
        self
    }

    /// The scene defines the program was compiled with (`Gpu::set_scene_defines`).
    pub fn scene_defines(&self) -> &[(&'static str, String)] {
        &self.program.scene_defines
    }

    /// The program's name (its fragment stage's file).
    pub fn program_name(&self) -> &str {
        &self.program.name
    }

    /// Makes the next draw fail with `error` (a binding found wrong).
    pub fn fail(&mut self, error: Error) -> &mut Self {
        self.error.get_or_insert(error);
        self
    }

    pub fn int(&mut self, name: &str, v: i32) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe { gl.uniform_1_i32(l, v) })
    }

    pub fn uint(&mut self, name: &str, v: u32) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe { gl.uniform_1_u32(l, v) })
    }

    pub fn float(&mut self, name: &str, v: f32) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe { gl.uniform_1_f32(l, v) })
    }

    pub fn vec2(&mut self, name: &str, v: [f32; 2]) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe { gl.uniform_2_f32(l, v[0], v[1]) })
    }

    pub fn vec3(&mut self, name: &str, v: [f32; 3]) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe {
            gl.uniform_3_f32(l, v[0], v[1], v[2])
        })
    }

    pub fn ivec2(&mut self, name: &str, v: [i32; 2]) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe { gl.uniform_2_i32(l, v[0], v[1]) })
    }

    pub fn ivec3(&mut self, name: &str, v: [i32; 3]) -> &mut Self {
        // SAFETY: as for `texture`.
        self.set(name, |gl, l| unsafe {
            gl.uniform_3_i32(l, v[0], v[1], v[2])
        })
    }

    /// Fails with the first undeclared uniform, else binds `target` over the
    /// viewport (x, y, w, h) and applies `state`.
    fn prepare(&mut self, target: &Target, state: &DrawState, viewport: [i32; 4]) -> Result<()> {
        if let Some(e) = self.error.take() {
            return Err(e);
        }
        target.bind_region(viewport[0], viewport[1], viewport[2], viewport[3]);
        self.program.gpu().apply(state);
        Ok(())
    }

    /// One full-screen triangle (3 vertices from gl_VertexID, no buffers).
    pub fn draw_fullscreen(&mut self, target: &Target, state: &DrawState) -> Result<()> {
        self.draw_region(target, state, whole(target))
    }

    /// A full-screen triangle clipped to the viewport (x, y, w, h) of
    /// `target`: a pass over one band of a texture (a photon frame).
    pub fn draw_region(
        &mut self,
        target: &Target,
        state: &DrawState,
        viewport: [i32; 4],
    ) -> Result<()> {
        self.prepare(target, state, viewport)?;
        let gpu = self.program.gpu();
        gpu.bind_empty_vertex_array();
        // SAFETY: gpu module doc; the vertex shader makes its vertices from
        // gl_VertexID, so no buffer is read.
        unsafe { self.gl.draw_arrays(glow::TRIANGLES, 0, 3) };
        Ok(())
    }

    /// Points `first..first + count` (positions from gl_VertexID in the
    /// vertex program).
    pub fn draw_points(
        &mut self,
        target: &Target,
        state: &DrawState,
        first: i32,
        count: i32,
    ) -> Result<()> {
        self.prepare(target, state, whole(target))?;
        self.program.gpu().bind_empty_vertex_array();
        // SAFETY: as for draw_region.
        unsafe { self.gl.draw_arrays(glow::POINTS, first, count) };
        Ok(())
    }

    /// The vertices of `vertices` as triangles (three a triangle), over the
    /// viewport (x, y, w, h) of `target`.
    pub fn draw_triangles(
        &mut self,
        target: &Target,
        state: &DrawState,
        viewport: [i32; 4],
        vertices: &VertexBuffer,
    ) -> Result<()> {
        self.prepare(target, state, viewport)?;
        // SAFETY: gpu module doc; the vertex array is the buffer's own and
        // describes `count` vertices.
        unsafe {
            self.gl.bind_vertex_array(Some(vertices.vao));
            self.gl
                .draw_arrays(glow::TRIANGLES, 0, vertices.count as i32);
        }
        Ok(())
    }

    /// Every vertex of `vertices` as a point.
    pub fn draw_vertices(
        &mut self,
        target: &Target,
        state: &DrawState,
        vertices: &VertexBuffer,
    ) -> Result<()> {
        self.prepare(target, state, whole(target))?;
        // SAFETY: gpu module doc; the vertex array is the buffer's own and
        // describes `count` vertices.
        unsafe {
            self.gl.bind_vertex_array(Some(vertices.vao));
            self.gl.draw_arrays(glow::POINTS, 0, vertices.count as i32);
        }
        Ok(())
    }
}

/// The viewport over all of `target`.
fn whole(target: &Target) -> [i32; 4] {
    [0, 0, target.width as i32, target.height as i32]
}
