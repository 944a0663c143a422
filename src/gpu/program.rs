//! GLSL programs from glsl/, embedded at build time, with `#include "path"`
//! (paths from glsl/) and compile errors reported as `glsl/<file>:<line>`.

use std::collections::{HashMap, HashSet};

use glow::HasContext;

use super::{Error, Gpu, Result, ShaderError};

include!(concat!(env!("OUT_DIR"), "/glsl_sources.rs"));

/// Every embedded GLSL file, path relative to glsl/.
pub fn glsl_files() -> impl Iterator<Item = (&'static str, &'static str)> {
    GLSL_SOURCES.iter().copied()
}

fn source_of(name: &str) -> Option<&'static str> {
    GLSL_SOURCES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, s)| *s)
}

/// A file of the embedded GLSL tree, as a program's source lookup.
fn embedded(name: &str) -> Option<String> {
    source_of(name).map(str::to_string)
}

/// The source a driver receives for `name` (includes resolved, the layout
/// constants and `defines` after #version), for offline compilers; None if a
/// file is missing.
pub fn preprocessed_source(name: &str, defines: &[(&str, String)]) -> Option<String> {
    preprocess(&embedded, name, &with_layout(defines))
        .ok()
        .map(|p| p.text)
}

/// The constants of src/layout.rs, then the program's own defines.
fn with_layout<'a>(defines: &[(&'a str, String)]) -> Vec<(&'a str, String)> {
    let mut all = crate::layout::glsl_defines();
    all.extend(defines.iter().cloned());
    all
}

/// Uniform names a preprocessed source declares (`uniform <type> <name>[...];`,
/// several names per line allowed), in the branches of `#ifdef` / `#ifndef` /
/// `#else` that its `#define`s make active: a name set in no active branch is
/// a misspelling, or a binding meant for another variant of the program.
fn declared_uniforms(text: &str) -> HashSet<String> {
    let mut names = HashSet::new();
    let mut defined = HashSet::new();
    // One entry per open conditional: whether its current branch is active.
    let mut active: Vec<bool> = Vec::new();
    for line in text.lines() {
        let line = line.trim_start();
        let word = |prefix: &str| {
            line.strip_prefix(prefix)
                .map(|r| r.split_whitespace().next().unwrap_or("").to_string())
        };
        let live = active.iter().all(|&a| a);
        if let Some(name) = word("#define ") {
            if live {
                defined.insert(name);
            }
        } else if let Some(name) = word("#ifdef ") {
            active.push(defined.contains(&name));
        } else if let Some(name) = word("#ifndef ") {
            active.push(!defined.contains(&name));
        } else if line.starts_with("#if") {
            active.push(true); // an expression: assume the branch is taken
        } else if line.starts_with("#else") {
            if let Some(a) = active.last_mut() {
                *a = !*a;
            }
        } else if line.starts_with("#endif") {
            active.pop();
        } else if live {
            declare(line, &mut names);
        }
    }
    names
}

/// The names a `uniform` declaration line declares, added to `names`.
fn declare(line: &str, names: &mut HashSet<String>) {
    let Some(rest) = line
        .strip_prefix("uniform ")
        .or_else(|| line.split_once(") uniform ").map(|(_, r)| r))
    else {
        return;
    };
    let decl = rest.split(';').next().unwrap_or("");
    // Skip the type (and any precision or memory qualifier): names follow
    // the last type word.
    let mut words = decl.splitn(2, char::is_whitespace);
    let mut ty = words.next().unwrap_or("");
    let mut list = words.next().unwrap_or("").trim_start();
    while matches!(
        ty,
        "highp" | "mediump" | "lowp" | "writeonly" | "readonly" | "coherent" | "restrict"
    ) {
        let mut w = list.splitn(2, char::is_whitespace);
        ty = w.next().unwrap_or("");
        list = w.next().unwrap_or("").trim_start();
    }
    for name in list.split(',') {
        let name = name.split(['[', '=']).next().unwrap_or("").trim();
        if !name.is_empty() {
            names.insert(name.to_string());
        }
    }
}

/// Source after `#include` resolution. Each file's lines are numbered
/// `id * LINE_STRIDE + line` with `#line`: drivers report line numbers faithfully
/// but not always the source-string number (Mesa 22 gives 0 for some errors),
/// so the file is encoded in the line itself.
const LINE_STRIDE: u32 = 1_000_000;

struct Preprocessed {
    text: String,
    files: Vec<String>,
}

fn preprocess(
    lookup: &dyn Fn(&str) -> Option<String>,
    root: &str,
    defines: &[(&str, String)],
) -> std::result::Result<Preprocessed, ShaderError> {
    let mut out = Preprocessed {
        text: String::new(),
        files: Vec::new(),
    };
    let mut included = HashMap::new();
    expand(lookup, root, None, defines, &mut out, &mut included)?;
    Ok(out)
}

fn expand(
    lookup: &dyn Fn(&str) -> Option<String>,
    name: &str,
    from: Option<(&str, u32)>,
    defines: &[(&str, String)],
    out: &mut Preprocessed,
    included: &mut HashMap<String, usize>,
) -> std::result::Result<(), ShaderError> {
    if included.contains_key(name) {
        return Ok(()); // every include is guarded: a helper is pasted once
    }
    let text = lookup(name).ok_or_else(|| {
        let (file, line) = from.map_or((name.to_string(), 0), |(f, l)| (f.to_string(), l));
        ShaderError {
            file,
            line,
            message: format!("no such GLSL file: glsl/{name}"),
            log: String::new(),
        }
    })?;
    let id = out.files.len();
    out.files.push(name.to_string());
    included.insert(name.to_string(), id);
    for (i, line) in text.lines().enumerate() {
        let line_no = i as u32 + 1;
        let trimmed = line.trim_start();
        if let Some(rest) = trimmed.strip_prefix("#include") {
            let path = rest.trim().trim_matches('"');
            expand(lookup, path, Some((name, line_no)), &[], out, included)?;
            out.text += &format!("#line {}\n", id as u32 * LINE_STRIDE + line_no + 1);
        } else if trimmed.starts_with("#version") {
            out.text += line;
            out.text.push('\n');
            for (k, v) in defines {
                out.text += &format!("#define {k} {v}\n");
            }
            out.text += &format!("#line {}\n", id as u32 * LINE_STRIDE + line_no + 1);
        } else {
            if line_no == 1 {
                out.text += &format!("#line {}\n", id as u32 * LINE_STRIDE + 1);
            }
            out.text += line;
            out.text.push('\n');
        }
    }
    Ok(())
}

/// Finds the first error in a driver log: Mesa writes `N:L(C): error: msg`,
/// NVIDIA `N(L) : error Cxxxx: msg`. Returns (source number, line, message).
fn parse_log(log: &str) -> Option<(usize, u32, String)> {
    let mut first = None;
    for l in log.lines() {
        let l = l.trim();
        let parsed = (|| {
            let (src, rest) = l.split_once([':', '('])?;
            let src: usize = src.trim().parse().ok()?;
            let rest = rest.trim_start();
            let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
            let line: u32 = digits.parse().ok()?;
            let msg = rest[digits.len()..]
                .trim_start_matches(|c: char| c.is_ascii_digit() || "():  ".contains(c))
                .trim()
                .to_string();
            Some((src, line, msg))
        })();
        if let Some(p) = parsed {
            if l.contains("error") {
                return Some(p);
            }
            first.get_or_insert(p);
        }
    }
    first
}

/// A linked vertex + fragment program.
pub struct Program {
    gpu: Gpu,
    pub(crate) raw: glow::Program,
    pub name: String,
    /// Every uniform either stage's source declares.
    declared: HashSet<String>,
    uniforms: std::cell::RefCell<HashMap<String, Option<glow::UniformLocation>>>,
    /// The scene defines it was compiled with: scene packing checks them
    /// against the scene it binds.
    pub(crate) scene_defines: Vec<(&'static str, String)>,
}

impl Program {
    /// A fragment program drawn over a full-screen triangle.
    pub fn fullscreen(gpu: &Gpu, fragment: &str) -> Result<Self> {
        Self::new(gpu, "common/fullscreen.vert", fragment, &[])
    }

    pub fn fullscreen_with(gpu: &Gpu, fragment: &str, defines: &[(&str, String)]) -> Result<Self> {
        Self::new(gpu, "common/fullscreen.vert", fragment, defines)
    }

    pub fn new(
        gpu: &Gpu,
        vertex: &str,
        fragment: &str,
        defines: &[(&str, String)],
    ) -> Result<Self> {
        Self::from_lookup(gpu, &embedded, vertex, fragment, defines)
    }

    /// A program with a geometry stage between the vertex and fragment ones.
    pub fn with_geometry(
        gpu: &Gpu,
        vertex: &str,
        geometry: &str,
        fragment: &str,
        defines: &[(&str, String)],
    ) -> Result<Self> {
        Self::build(gpu, &embedded, [vertex, fragment], Some(geometry), defines)
    }

    /// Builds from any source lookup: the embedded tree, or (in tests) a tree
    /// with a deliberately broken file.
    pub fn from_lookup(
        gpu: &Gpu,
        lookup: &dyn Fn(&str) -> Option<String>,
        vertex: &str,
        fragment: &str,
        defines: &[(&str, String)],
    ) -> Result<Self> {
        Self::build(gpu, lookup, [vertex, fragment], None, defines)
    }

    fn build(
        gpu: &Gpu,
        lookup: &dyn Fn(&str) -> Option<String>,
        [vertex, fragment]: [&str; 2],
        geometry: Option<&str>,
        defines: &[(&str, String)],
    ) -> Result<Self> {
        let mut defines = with_layout(defines);
        let scene_defines: Vec<(&'static str, String)> = gpu
            .scene_defines()
            .into_iter()
            .filter(|(name, _)| !defines.iter().any(|(n, _)| n == name))
            .collect();
        defines.extend(scene_defines.iter().map(|(n, v)| (*n, v.clone())));
        let vs_source = preprocess(lookup, vertex, &defines)?;
        let fs_source = preprocess(lookup, fragment, &defines)?;
        let gs_source = geometry
            .map(|g| preprocess(lookup, g, &defines))
            .transpose()?;
        let mut declared = declared_uniforms(&vs_source.text);
        declared.extend(declared_uniforms(&fs_source.text));
        if let Some(g) = &gs_source {
            declared.extend(declared_uniforms(&g.text));
        }
        let vs = compile(gpu, glow::VERTEX_SHADER, vertex, &vs_source)?;
        let gl = gpu.gl();
        let gs = match (geometry, &gs_source) {
            (Some(name), Some(source)) => match compile(gpu, glow::GEOMETRY_SHADER, name, source) {
                Ok(gs) => Some(gs),
                Err(e) => {
                    // SAFETY: gpu module doc; the shader was made just above.
                    unsafe { gl.delete_shader(vs) };
                    return Err(e);
                }
            },
            _ => None,
        };
        let fs = match compile(gpu, glow::FRAGMENT_SHADER, fragment, &fs_source) {
            Ok(fs) => fs,
            Err(e) => {
                // SAFETY: gpu module doc; the shaders were made just above.
                unsafe {
                    gl.delete_shader(vs);
                    if let Some(gs) = gs {
                        gl.delete_shader(gs);
                    }
                }
                return Err(e);
            }
        };
        // SAFETY: gpu module doc; both shaders compiled on this context, and
        // each object is deleted on every path that does not return it.
        unsafe {
            let raw = gl
                .create_program()
                .map_err(Error::creating(format!("the program glsl/{fragment}")))?;
            gl.attach_shader(raw, vs);
            gl.attach_shader(raw, fs);
            if let Some(gs) = gs {
                gl.attach_shader(raw, gs);
            }
            gl.link_program(raw);
            gl.delete_shader(vs);
            gl.delete_shader(fs);
            if let Some(gs) = gs {
                gl.delete_shader(gs);
            }
            if !gl.get_program_link_status(raw) {
                let log = gl.get_program_info_log(raw);
                gl.delete_program(raw);
                return Err(ShaderError {
                    file: fragment.to_string(),
                    line: 0,
                    message: format!("link error with glsl/{vertex}"),
                    log,
                }
                .into());
            }
            Ok(Self {
                gpu: gpu.clone(),
                raw,
                name: fragment.to_string(),
                declared,
                uniforms: Default::default(),
                scene_defines,
            })
        }
    }

    pub(super) fn gpu(&self) -> &Gpu {
        &self.gpu
    }

    /// The location of a uniform the program declares (None when the driver
    /// optimised it away); an error for a name neither source declares.
    pub(super) fn uniform(&self, name: &str) -> Result<Option<glow::UniformLocation>> {
        if let Some(l) = self.uniforms.borrow().get(name) {
            return Ok(*l);
        }
        if !self.declared.contains(name) {
            return Err(Error::UndeclaredUniform {
                program: self.name.clone(),
                name: name.to_string(),
            });
        }
        // SAFETY: gpu module doc; the program is this value's own.
        let location = unsafe { self.gpu.gl().get_uniform_location(self.raw, name) };
        self.uniforms
            .borrow_mut()
            .insert(name.to_string(), location);
        Ok(location)
    }
}

fn compile(gpu: &Gpu, stage: u32, name: &str, pre: &Preprocessed) -> Result<glow::Shader> {
    let gl = gpu.gl();
    // SAFETY: gpu module doc; the shader is deleted if it does not compile.
    let log = unsafe {
        let sh = gl
            .create_shader(stage)
            .map_err(Error::creating(format!("a shader for glsl/{name}")))?;
        gl.shader_source(sh, &pre.text);
        gl.compile_shader(sh);
        if gl.get_shader_compile_status(sh) {
            return Ok(sh);
        }
        let log = gl.get_shader_info_log(sh);
        gl.delete_shader(sh);
        log
    };
    let (file, line, message) = match parse_log(&log) {
        Some((_, line, msg)) => (
            pre.files
                .get((line / LINE_STRIDE) as usize)
                .cloned()
                .unwrap_or_else(|| name.to_string()),
            line % LINE_STRIDE,
            msg,
        ),
        None => (name.to_string(), 0, "compile error".to_string()),
    };
    Err(ShaderError {
        file,
        line,
        message,
        log,
    }
    .into())
}

impl Drop for Program {
    fn drop(&mut self) {
        // SAFETY: gpu module doc; the program is this value's own.
        unsafe { self.gpu.gl().delete_program(self.raw) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mesa_and_nvidia_logs_parse() {
        assert_eq!(
            parse_log("0:12(5): error: `foo' undeclared\n"),
            Some((0, 12, "error: `foo' undeclared".to_string()))
        );
        let (src, line, _) = parse_log("2(7) : error C1008: undefined variable \"x\"").unwrap();
        assert_eq!((src, line), (2, 7));
    }

    #[test]
    fn declared_uniforms_are_read_from_the_source() {
        let names = declared_uniforms(
            "#version 450 core\nuniform sampler2D u_a; // x\n  uniform highp int u_b, u_c[4];\nlayout(binding = 0) uniform vec3 u_d;\nfloat uniform_x;\nlayout(rgba32f) uniform writeonly image2D u_e;\n",
        );
        let mut names: Vec<_> = names.into_iter().collect();
        names.sort();
        assert_eq!(names, ["u_a", "u_b", "u_c", "u_d", "u_e"]);
        // Only the branches the defines make active.
        let names = declared_uniforms(
            "#version 450 core\n#define A 1\n#ifdef A\nuniform int u_a;\n#else\nuniform int u_not_a;\n#endif\n#ifdef B\nuniform int u_b;\n#endif\n#ifndef B\nuniform int u_not_b;\n#endif\n",
        );
        let mut names: Vec<_> = names.into_iter().collect();
        names.sort();
        assert_eq!(names, ["u_a", "u_not_b"]);
    }

    #[test]
    fn includes_map_back_to_their_files() {
        let files: HashMap<&str, &str> = [
            (
                "a.frag",
                "#version 450 core\n#include \"b.glsl\"\nvoid main() {}\n",
            ),
            ("b.glsl", "float b() { return 1.0; }\n#include \"a.frag\"\n"),
        ]
        .into();
        let lookup = |n: &str| files.get(n).map(|s| s.to_string());
        let p = preprocess(&lookup, "a.frag", &[("K", "3".into())]).unwrap();
        assert_eq!(p.files, vec!["a.frag", "b.glsl"]);
        assert!(p
            .text
            .starts_with("#version 450 core\n#define K 3\n#line 2\n"));
        assert!(p.text.contains("#line 1000001\nfloat b()"));
        assert!(p.text.contains("#line 3\nvoid main"));
    }
}
