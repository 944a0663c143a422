//! OBJ meshes and their MTL materials, as the scene loader needs them: the
//! triangles (tobj parses them, triangulating polygons as fans), each with
//! its group or object (`g`, `o`), its MTL material, the line of its face,
//! and its vertex normals (`vn`) when every corner of its face gives one.
//!
//! tobj reports no line numbers, and it accepts some malformed input
//! silently (a `usemtl` naming no material, a NaN coordinate) or, for a
//! colour of fewer than three numbers in an MTL file, panics. So each file
//! is first pre-scanned here, line by line, just far enough to refuse what
//! is wrong with its file and line: a number that does not parse, a
//! coordinate or normal that is not finite (or a zero normal), a face index
//! out of range, a face of fewer than 3 corners, a missing MTL file, an
//! unknown `usemtl` name, an MTL statement tobj would choke on. Only then is
//! the text handed to tobj (`load_obj_buf`, and `load_mtl_buf` for each
//! `mtllib`), which does the real parse.
//!
//! Files are read from disk, or, for an embedded scene whose files are not
//! on disk, from their embedded copies (`embedded::file`).

use std::collections::HashMap;
use std::io::Cursor;
use std::path::{Path, PathBuf};

use glam::Vec3;

use super::defaults::IOR_RANGE;
use super::Material;

/// Coordinates beyond this magnitude are refused (they are not a mesh).
const MAX_OBJ_COORDINATE: f32 = 1e30;

/// One triangle of an OBJ file.
#[derive(Clone, Debug, PartialEq)]
pub struct ObjTriangle {
    /// Positions as written. When the face has vertex normals and its
    /// winding disagrees with them (its geometric normal points away from
    /// the sum of its vertex normals), v1 and v2 are swapped, normals too:
    /// the geometric normal then always lies on the normals' side, which
    /// decides inside and outside for glass and the front of an emitter.
    pub corners: [Vec3; 3],
    /// Unit vertex normals at the corners, when the face gives one at each.
    pub normals: Option<[Vec3; 3]>,
    /// Index into `ObjMesh::objects`.
    pub object: usize,
    /// Index into `ObjMesh::materials` (None: no `usemtl` before the face).
    pub material: Option<usize>,
    /// The line of the face (`f`) in the OBJ file.
    pub line: usize,
}

/// One MTL material and where it was defined.
#[derive(Clone, Debug)]
pub struct MtlMaterial {
    pub name: String,
    /// The material as tobj read it.
    pub mtl: tobj::Material,
    /// The MTL file and the line of each statement (the last one of each key).
    pub file: PathBuf,
    pub lines: HashMap<String, usize>,
}

/// An OBJ file's triangles, groups and objects, and MTL materials.
#[derive(Clone, Debug, Default)]
pub struct ObjMesh {
    pub triangles: Vec<ObjTriangle>,
    /// The names of its groups and objects (`g`, `o`; `unnamed_object`
    /// before the first), each once, in order of appearance.
    pub objects: Vec<String>,
    /// MTL materials, in the order of the `mtllib` files and, within each,
    /// of the file (tobj's `material_id` indexes this).
    pub materials: Vec<MtlMaterial>,
}

/// The text of a file a scene refers to: from disk, or, when no such file
/// exists and the path lies under `scenes/`, its embedded copy. The error
/// says why it cannot be read.
pub fn read_text(path: &Path) -> Result<String, String> {
    if !path.exists() {
        if let Some(text) = super::embedded::file(path) {
            return Ok(text.to_string());
        }
        return Err("no such file".into());
    }
    std::fs::read_to_string(path).map_err(|e| e.to_string())
}

/// Loads `path`. With `with_mtl` false (the scene gives a `material` for
/// the whole mesh) the MTL files are not read, and `usemtl` names are not
/// checked: every triangle's `material` is None.
pub fn load(path: &Path, with_mtl: bool) -> Result<ObjMesh, String> {
    let text =
        read_text(path).map_err(|e| format!("cannot read OBJ file {}: {e}", path.display()))?;
    let scan = prescan_obj(&text, path, with_mtl)?;
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let libraries = &scan.libraries;
    // The pre-scan refuses every input tobj is known to panic on; should
    // another one turn up, it is still a refusal, not a crash.
    let parsed = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        tobj::load_obj_buf(
            &mut Cursor::new(text.as_bytes()),
            &opts,
            |p| match libraries.iter().find(|l| l.written == p) {
                Some(l) if with_mtl => tobj::load_mtl_buf(&mut Cursor::new(l.text.as_bytes())),
                _ => Ok((Vec::new(), Default::default())),
            },
        )
    }))
    .map_err(|_| {
        format!(
            "OBJ file {}: tobj could not parse it (or its MTL files)",
            path.display()
        )
    })?;
    let (models, _) = parsed.map_err(|e| format!("OBJ file {}: {e}", path.display()))?;
    let materials = scan
        .libraries
        .iter()
        .flat_map(|l| l.materials(with_mtl))
        .collect::<Result<Vec<_>, _>>()?;
    let mut mesh = ObjMesh {
        materials,
        ..ObjMesh::default()
    };
    let mut faces = scan
        .faces
        .iter()
        .flat_map(|f| (0..f.corners.saturating_sub(2)).map(move |k| (f, k + 1)));
    for model in &models {
        let object = match mesh.objects.iter().position(|o| *o == model.name) {
            Some(i) => i,
            None => {
                mesh.objects.push(model.name.clone());
                mesh.objects.len() - 1
            }
        };
        let m = &model.mesh;
        let position = |i: u32| -> Vec3 {
            let i = i as usize * 3;
            Vec3::from_slice(&m.positions[i..i + 3])
        };
        for tri in m.indices.chunks_exact(3) {
            let Some((face, k)) = faces.next() else {
                return Err(format!(
                    "OBJ file {}: tobj read more triangles than the file's faces give (a bug)",
                    path.display()
                ));
            };
            let corners = [position(tri[0]), position(tri[1]), position(tri[2])];
            let normals = face
                .normals
                .as_ref()
                .map(|n| [n[0], n[k], n[k + 1]].map(|i| scan.normals[i]));
            mesh.triangles.push(oriented(ObjTriangle {
                corners,
                normals,
                object,
                material: m.material_id.filter(|_| with_mtl),
                line: face.line,
            }));
        }
    }
    if faces.next().is_some() {
        return Err(format!(
            "OBJ file {}: tobj read fewer triangles than the file's faces give (a bug)",
            path.display()
        ));
    }
    if mesh.triangles.is_empty() {
        return Err(format!("OBJ file {} holds no triangles", path.display()));
    }
    Ok(mesh)
}

/// The triangle turned around when its winding disagrees with its normals.
fn oriented(mut t: ObjTriangle) -> ObjTriangle {
    if let Some([n0, n1, n2]) = t.normals {
        let [v0, v1, v2] = t.corners;
        if (v1 - v0).cross(v2 - v0).dot(n0 + n1 + n2) < 0.0 {
            t.corners = [v0, v2, v1];
            t.normals = Some([n0, n2, n1]);
        }
    }
    t
}

// ---- the pre-scan ---------------------------------------------------------------

/// One face line: its line, corners, and (when every corner gives one) the
/// 0-based indices of its vertex normals.
struct FaceScan {
    line: usize,
    corners: usize,
    normals: Option<Vec<usize>>,
}

/// An MTL material's name and the line of each of its statements.
type MtlNames = Vec<(String, HashMap<String, usize>)>;

/// An `mtllib` the OBJ names: as written, its path, text, and its materials'
/// names and statement lines.
struct Library {
    written: PathBuf,
    path: PathBuf,
    text: String,
    names: MtlNames,
}

impl Library {
    /// Its materials as tobj reads them (none when MTL files are not used).
    fn materials(&self, with_mtl: bool) -> Vec<Result<MtlMaterial, String>> {
        if !with_mtl {
            return Vec::new();
        }
        let parsed =
            std::panic::catch_unwind(|| tobj::load_mtl_buf(&mut Cursor::new(self.text.as_bytes())));
        match parsed.unwrap_or(Err(tobj::LoadError::GenericFailure)) {
            Err(e) => vec![Err(format!("MTL file {}: {e}", self.path.display()))],
            Ok((mats, _)) if mats.len() != self.names.len() => vec![Err(format!(
                "MTL file {}: tobj read {} materials where the file defines {}",
                self.path.display(),
                mats.len(),
                self.names.len()
            ))],
            Ok((mats, _)) => mats
                .into_iter()
                .zip(&self.names)
                .map(|(mtl, (_, lines))| {
                    Ok(MtlMaterial {
                        name: mtl.name.clone(),
                        mtl,
                        file: self.path.clone(),
                        lines: lines.clone(),
                    })
                })
                .collect(),
        }
    }
}

struct Scan {
    faces: Vec<FaceScan>,
    normals: Vec<Vec3>,
    libraries: Vec<Library>,
}

/// Counts of what the lines before the current one defined.
#[derive(Default)]
struct Counts {
    positions: usize,
    texcoords: usize,
    normals: usize,
}

/// Checks every line tobj will read; refuses the first bad one by its line.
fn prescan_obj(text: &str, path: &Path, with_mtl: bool) -> Result<Scan, String> {
    let mut scan = Scan {
        faces: Vec::new(),
        normals: Vec::new(),
        libraries: Vec::new(),
    };
    let mut counts = Counts::default();
    for (i, line) in text.lines().enumerate() {
        let at = |message: String| format!("OBJ file {}:{}: {message}", path.display(), i + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let p = position(words).map_err(at)?;
                if let Some(bad) = p
                    .iter()
                    .find(|c| !c.is_finite() || c.abs() > MAX_OBJ_COORDINATE)
                {
                    return Err(at(format!(
                        "v: coordinate {bad} is not a finite number within {MAX_OBJ_COORDINATE:e}"
                    )));
                }
                counts.positions += 1;
            }
            Some("vt") => {
                numbers(words, 2, "vt", false).map_err(at)?;
                counts.texcoords += 1;
            }
            Some("vn") => {
                let n = numbers(words, 3, "vn", false).map_err(at)?;
                let n = Vec3::new(n[0], n[1], n[2]);
                if !n.is_finite() || n.length_squared() == 0.0 || !n.normalize().is_finite() {
                    return Err(at(format!(
                        "vn: {:?} is not a usable normal (finite, not zero)",
                        n.to_array()
                    )));
                }
                scan.normals.push(n.normalize());
                counts.normals += 1;
            }
            Some("f") => {
                let face = face(words, &counts).map_err(at)?;
                if face.corners < 3 {
                    return Err(at(format!(
                        "f: a face needs at least 3 corners, this one has {}",
                        face.corners
                    )));
                }
                scan.faces.push(FaceScan {
                    line: i + 1,
                    ..face
                });
            }
            // Lines are skipped, but tobj parses their indices as a face's.
            Some("l") => {
                face(words, &counts).map_err(at)?;
            }
            Some("usemtl") if line.split_once(' ').unwrap_or_default().1.trim().is_empty() => {
                return Err(at("usemtl: no material named".into()));
            }
            Some("mtllib") if with_mtl => {
                let written = line.split_once(' ').unwrap_or_default().1.trim();
                if written.is_empty() {
                    return Err(at("mtllib: no file named".into()));
                }
                let full = path.parent().unwrap_or(Path::new(".")).join(written);
                let text = read_text(&full).map_err(|e| {
                    at(format!(
                        "mtllib: cannot read MTL file {}: {e}",
                        full.display()
                    ))
                })?;
                // Errors inside it name the MTL file and its line.
                let names = prescan_mtl(&text, &full)?;
                scan.libraries.push(Library {
                    written: PathBuf::from(written),
                    path: full,
                    text,
                    names,
                });
            }
            Some("usemtl") if with_mtl => {
                let name = line.split_once(' ').unwrap_or_default().1.trim();
                let known = scan
                    .libraries
                    .iter()
                    .flat_map(|l| &l.names)
                    .any(|(n, _)| n == name);
                if !known {
                    return Err(at(format!(
                        "usemtl {name:?}: no such material in the MTL files named before this line ({})",
                        library_names(&scan.libraries)
                    )));
                }
            }
            _ => {}
        }
    }
    Ok(scan)
}

/// "a.mtl (red, white)", or "none".
fn library_names(libraries: &[Library]) -> String {
    if libraries.is_empty() {
        return "no mtllib".into();
    }
    libraries
        .iter()
        .map(|l| {
            let names: Vec<&str> = l.names.iter().map(|(n, _)| n.as_str()).collect();
            format!("{}: {}", l.written.display(), names.join(", "))
        })
        .collect::<Vec<_>>()
        .join("; ")
}

/// `count` numbers (f32, as tobj reads them); more are an error when `exact`.
fn numbers<'a>(
    mut words: impl Iterator<Item = &'a str>,
    count: usize,
    what: &str,
    exact: bool,
) -> Result<Vec<f32>, String> {
    let mut out = Vec::with_capacity(count);
    for k in 0..count {
        let Some(w) = words.next() else {
            return Err(format!("{what}: expected {count} numbers, found {k}"));
        };
        out.push(
            w.parse::<f32>()
                .map_err(|_| format!("{what}: `{w}` is not a number"))?,
        );
    }
    if exact && words.next().is_some() {
        return Err(format!("{what}: more than {count} numbers"));
    }
    Ok(out)
}

/// A `v` line's position: x y z, then nothing, w (dividing them, not 0),
/// or a colour r g b, as tobj allows.
fn position<'a>(mut words: impl Iterator<Item = &'a str>) -> Result<[f32; 3], String> {
    let xyz = numbers(&mut words, 3, "v", false)?;
    let rest: Vec<&str> = words.collect();
    let w = match rest.len() {
        0 => 1.0,
        1 => {
            let w = numbers(rest.iter().copied(), 1, "v (w)", true)?[0];
            if w == 0.0 || !w.is_finite() {
                return Err(format!("v: w = {w} (it divides the coordinates)"));
            }
            w
        }
        3 => {
            numbers(rest.iter().copied(), 3, "v (colour)", true)?;
            1.0
        }
        n => return Err(format!("v: {} numbers (3, 4 or 6 allowed)", 3 + n)),
    };
    Ok([xyz[0] / w, xyz[1] / w, xyz[2] / w])
}

/// A face's corners (`v`, `v/vt`, `v//vn`, `v/vt/vn`; negative = relative),
/// each index within what the lines before it defined.
fn face<'a>(words: impl Iterator<Item = &'a str>, counts: &Counts) -> Result<FaceScan, String> {
    let mut corners = 0;
    let mut normals = Some(Vec::new());
    for corner in words {
        corners += 1;
        let parts: Vec<&str> = corner.split('/').collect();
        if parts.len() > 3 {
            return Err(format!("f: corner `{corner}` has more than 3 indices"));
        }
        let kinds = [
            ("vertex", "vertices", counts.positions),
            (
                "texture coordinate",
                "texture coordinates",
                counts.texcoords,
            ),
            ("normal", "normals", counts.normals),
        ];
        let mut indices = [None; 3];
        for (k, part) in parts.iter().enumerate() {
            if part.is_empty() && k > 0 {
                continue;
            }
            let (what, plural, defined) = kinds[k];
            let i: isize = part
                .parse()
                .map_err(|_| format!("f: corner `{corner}`: `{part}` is not an index"))?;
            let resolved = if i < 0 { defined as isize + i } else { i - 1 };
            if i == 0 || resolved < 0 || resolved >= defined as isize {
                return Err(format!(
                    "f: corner `{corner}` refers to {what} {i}, but {defined} {plural} are defined before this line"
                ));
            }
            indices[k] = Some(resolved as usize);
        }
        match (&mut normals, indices[2]) {
            (Some(list), Some(n)) => list.push(n),
            _ => normals = None,
        }
    }
    Ok(FaceScan {
        line: 0,
        corners,
        normals,
    })
}

/// Checks every MTL line tobj reads (it panics on a colour of fewer than
/// three numbers); returns each material's name and statement lines.
fn prescan_mtl(text: &str, path: &Path) -> Result<MtlNames, String> {
    let mut out: MtlNames = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let at = |message: String| format!("MTL file {}:{}: {message}", path.display(), i + 1);
        let line = raw.trim();
        let mut words = line.split_whitespace();
        let Some(key) = words.next() else { continue };
        match key {
            "newmtl" => {
                let name = line[6..].trim();
                if name.is_empty() {
                    return Err(at("newmtl: no name".into()));
                }
                out.push((name.to_string(), HashMap::new()));
            }
            "Ka" | "Kd" | "Ks" | "Ke" => {
                let c = numbers(words, 3, key, false).map_err(at)?;
                if c.iter().any(|x| !x.is_finite()) {
                    return Err(at(format!("{key}: {c:?} is not finite")));
                }
            }
            "Ns" | "Ni" | "d" => {
                let v = numbers(words, 1, key, false).map_err(at)?[0];
                if !v.is_finite() {
                    return Err(at(format!("{key}: {v} is not finite")));
                }
            }
            "illum" => {
                let w = words.next().unwrap_or("");
                if w.parse::<u8>().is_err() {
                    return Err(at(format!(
                        "illum: `{w}` is not an illumination model (0..=10)"
                    )));
                }
            }
            "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "map_Ns" | "map_ns"
            | "map_NS" | "bump" | "map_d"
                if line[key.len()..].trim().is_empty() =>
            {
                return Err(at(format!("{key}: no file named")));
            }
            _ => {}
        }
        if let Some((_, lines)) = out.last_mut() {
            lines.insert(key.to_string(), i + 1);
        }
    }
    Ok(out)
}

// ---- MTL materials as the renderer's --------------------------------------------

/// An MTL material as one of the renderer's, by the first rule that applies
/// (the book, "OBJ meshes and MTL materials"):
/// 1. `Ke` with a channel above 0: an emitter of radiance Ke, from each
///    triangle's front face (its Kd is not used: emitters reflect nothing);
/// 2. `illum 7`, or `illum 4` or `6` with `Ni` other than 1: glass of ior Ni;
/// 3. `illum 3` or `5` with `Ks` above 0: a mirror of reflectance Ks;
/// 4. otherwise diffuse, of albedo Kd.
///
/// Errors name the MTL file and the line of the statement at fault.
pub fn renderer_material(m: &MtlMaterial) -> Result<Material, String> {
    let line = |key: &str| {
        let l = m
            .lines
            .get(key)
            .or_else(|| m.lines.get("newmtl"))
            .copied()
            .unwrap_or(0);
        format!("MTL file {}:{l}: material {:?}", m.file.display(), m.name)
    };
    let rgb = |c: [f32; 3]| Vec3::from(c);
    let illum = m.mtl.illumination_model;
    if let Some(ke) = m.mtl.emissive.map(rgb).filter(|c| c.max_element() > 0.0) {
        if ke.min_element() < 0.0 {
            return Err(format!(
                "{}: Ke {:?}: each channel must be >= 0",
                line("Ke"),
                ke.to_array()
            ));
        }
        return Ok(Material::Emitter {
            radiance: ke,
            normal: None,
        });
    }
    let ni = m.mtl.optical_density;
    if illum == Some(7) || (matches!(illum, Some(4 | 6)) && ni.is_some_and(|n| n != 1.0)) {
        let Some(ior) = ni else {
            return Err(format!(
                "{}: illum 7 is glass, which needs Ni (its index of refraction)",
                line("illum")
            ));
        };
        let (lo, hi) = IOR_RANGE;
        if !(lo..=hi).contains(&ior) {
            return Err(format!(
                "{}: Ni {ior} is outside the allowed range [{lo}, {hi}]",
                line("Ni")
            ));
        }
        return Ok(Material::Glass { ior });
    }
    let unit = |key: &str, c: Vec3| {
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            Err(format!(
                "{}: {key} {:?}: each channel must be in [0, 1] (energy conservation)",
                line(key),
                c.to_array()
            ))
        } else {
            Ok(c)
        }
    };
    if let (Some(3 | 5), Some(ks)) = (illum, m.mtl.specular.map(rgb)) {
        if ks.max_element() > 0.0 {
            return Ok(Material::Mirror {
                reflectance: unit("Ks", ks)?,
            });
        }
    }
    match m.mtl.diffuse.map(rgb) {
        Some(kd) => Ok(Material::Diffuse {
            albedo: unit("Kd", kd)?,
        }),
        None => Err(format!(
            "{}: no Kd, Ke, or mirror or glass statement: nothing says what it is",
            line("newmtl")
        )),
    }
}
