//! GLSL programs from glsl/, embedded at build time, with `#include "path"`
//! (paths from glsl/) and compile errors reported as `glsl/<file>:<line>`.

use std::collections::HashMap;

use glow::HasContext;

use super::{Gpu, GpuError};

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

/// The source a driver receives for `name` (includes resolved, `defines`
/// after #version), for offline compilers; None if a file is missing.
pub fn preprocessed_source(name: &str, defines: &[(&str, String)]) -> Option<String> {
    let lookup = |n: &str| source_of(n).map(str::to_string);
    preprocess(&lookup, name, defines).ok().map(|p| p.text)
}

/// A shader that did not compile or link, located in its glsl/ file.
#[derive(Debug, thiserror::Error)]
#[error("glsl/{file}:{line}: {message}\n--- driver log ---\n{log}")]
pub struct ShaderError {
    pub file: String,
    pub line: u32,
    pub message: String,
    pub log: String,
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
) -> Result<Preprocessed, ShaderError> {
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
) -> Result<(), ShaderError> {
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
    pub raw: glow::Program,
    pub name: String,
    uniforms: std::cell::RefCell<HashMap<String, Option<glow::UniformLocation>>>,
}

impl Program {
    /// A fragment program drawn over a full-screen triangle.
    pub fn fullscreen(gpu: &Gpu, fragment: &str) -> Result<Self, GpuError> {
        Self::new(gpu, "common/fullscreen.vert", fragment, &[])
    }

    pub fn fullscreen_with(
        gpu: &Gpu,
        fragment: &str,
        defines: &[(&str, String)],
    ) -> Result<Self, GpuError> {
        Self::new(gpu, "common/fullscreen.vert", fragment, defines)
    }

    pub fn new(
        gpu: &Gpu,
        vertex: &str,
        fragment: &str,
        defines: &[(&str, String)],
    ) -> Result<Self, GpuError> {
        let lookup = |n: &str| source_of(n).map(str::to_string);
        Self::from_lookup(gpu, &lookup, vertex, fragment, defines)
    }

    /// Builds from any source lookup: the embedded tree, or (in tests) a tree
    /// with a deliberately broken file.
    pub fn from_lookup(
        gpu: &Gpu,
        lookup: &dyn Fn(&str) -> Option<String>,
        vertex: &str,
        fragment: &str,
        defines: &[(&str, String)],
    ) -> Result<Self, GpuError> {
        let gl = gpu.gl();
        let vs = compile(gpu, lookup, glow::VERTEX_SHADER, vertex, defines)?;
        let fs = match compile(gpu, lookup, glow::FRAGMENT_SHADER, fragment, defines) {
            Ok(fs) => fs,
            Err(e) => {
                unsafe { gl.delete_shader(vs) };
                return Err(e);
            }
        };
        unsafe {
            let raw = gl.create_program().map_err(GpuError::Gl)?;
            gl.attach_shader(raw, vs);
            gl.attach_shader(raw, fs);
            gl.link_program(raw);
            gl.delete_shader(vs);
            gl.delete_shader(fs);
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
                uniforms: Default::default(),
            })
        }
    }

    pub(super) fn gpu_ctx(&self) -> &super::GlContext {
        &self.gpu.ctx
    }

    pub(super) fn uniform(&self, name: &str) -> Option<glow::UniformLocation> {
        self.uniforms
            .borrow_mut()
            .entry(name.to_string())
            .or_insert_with(|| unsafe { self.gpu.gl().get_uniform_location(self.raw, name) })
            .as_ref()
            .copied()
    }
}

fn compile(
    gpu: &Gpu,
    lookup: &dyn Fn(&str) -> Option<String>,
    stage: u32,
    name: &str,
    defines: &[(&str, String)],
) -> Result<glow::Shader, GpuError> {
    let pre = preprocess(lookup, name, defines)?;
    let gl = gpu.gl();
    unsafe {
        let sh = gl.create_shader(stage).map_err(GpuError::Gl)?;
        gl.shader_source(sh, &pre.text);
        gl.compile_shader(sh);
        if gl.get_shader_compile_status(sh) {
            return Ok(sh);
        }
        let log = gl.get_shader_info_log(sh);
        gl.delete_shader(sh);
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
}

impl Drop for Program {
    fn drop(&mut self) {
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
