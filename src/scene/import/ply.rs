//! PLY meshes (ASCII, binary little and big endian) through ply-rs-bw:
//! `vertex` positions (x, y, z), normals (nx, ny, nz) and texture
//! coordinates (u, v; s, t; texture_u, texture_v) where present, and `face`
//! lists (`vertex_indices` or `vertex_index`, any count and index type)
//! fanned into triangles. Errors say the line (ASCII) or, in binary data,
//! the line of `end_header` after which the data stands.

use glam::DVec3;
use ply_rs_bw::parser::Parser;
use ply_rs_bw::ply::{DefaultElement, Encoding, Property};

use super::geometry::Mesh;

/// A PLY error: the 1-based line (0 when unknown) and what is wrong.
#[derive(Clone, Debug, PartialEq)]
pub struct PlyError {
    pub line: usize,
    pub message: String,
}

fn err(line: usize, message: impl Into<String>) -> PlyError {
    PlyError {
        line,
        message: message.into(),
    }
}

/// The most vertices or faces a PLY file may declare.
pub const MAX_ELEMENTS: usize = 1 << 26;

/// A PLY file's bytes as a mesh.
pub fn parse_ply(bytes: &[u8]) -> Result<Mesh, PlyError> {
    let header_lines = header_lines(bytes);
    let parser = Parser::<DefaultElement>::new();
    let header = parser
        .read_ply_header(&mut &bytes[..])
        .map_err(|e| err(e.line().unwrap_or(0), first_line(&e.to_string())))?;
    for (name, e) in &header.elements {
        if e.count > MAX_ELEMENTS {
            return Err(err(
                0,
                format!(
                    "element {name} declares {} entries, more than the {MAX_ELEMENTS} allowed",
                    e.count
                ),
            ));
        }
    }
    let binary = header.encoding != Encoding::Ascii;
    let ply = parser.read_ply(&mut &bytes[..]).map_err(|e| {
        let line = match (binary, e.line()) {
            (false, Some(l)) => l,
            _ => header_lines,
        };
        let what = if binary {
            "binary data after end_header"
        } else {
            "data"
        };
        err(line, format!("{what}: {}", first_line(&e.to_string())))
    })?;
    let vertices = ply
        .payload
        .get("vertex")
        .ok_or_else(|| err(0, "no `vertex` element"))?;
    let faces = ply
        .payload
        .get("face")
        .ok_or_else(|| err(0, "no `face` element"))?;
    let at = |line| if binary { header_lines } else { line };
    let mut mesh = read_vertices(vertices).map_err(|m| err(at(0), m))?;
    for (i, f) in faces.iter().enumerate() {
        let face_line = header_lines + vertices.len() + i + 1;
        let idx = face_indices(f).map_err(|m| err(at(face_line), format!("face {i}: {m}")))?;
        if idx.len() < 3 {
            return Err(err(
                at(face_line),
                format!(
                    "face {i} has {} vertices; a face needs 3 or more",
                    idx.len()
                ),
            ));
        }
        for k in 1..idx.len() - 1 {
            mesh.triangles.push([idx[0], idx[k], idx[k + 1]]);
        }
    }
    mesh.check().map_err(|m| err(0, m))?;
    Ok(mesh)
}

/// The line `end_header` is on (1-based), or 0.
fn header_lines(bytes: &[u8]) -> usize {
    let end = b"end_header";
    let mut line = 1;
    let mut start = 0;
    for (i, &b) in bytes.iter().enumerate() {
        if b == b'\n' {
            if bytes[start..i].trim_ascii() == end {
                return line;
            }
            line += 1;
            start = i + 1;
        }
    }
    0
}

fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").trim().to_string()
}

fn scalar(p: &Property) -> Option<f64> {
    Some(match *p {
        Property::Char(v) => f64::from(v),
        Property::UChar(v) => f64::from(v),
        Property::Short(v) => f64::from(v),
        Property::UShort(v) => f64::from(v),
        Property::Int(v) => f64::from(v),
        Property::UInt(v) => f64::from(v),
        Property::Float(v) => f64::from(v),
        Property::Double(v) => v,
        _ => return None,
    })
}

fn read_vertices(vertices: &[DefaultElement]) -> Result<Mesh, String> {
    let mut mesh = Mesh::default();
    let Some(first) = vertices.first() else {
        return Ok(mesh);
    };
    let has = |k: &str| first.contains_key(k);
    let uv_keys = [("u", "v"), ("s", "t"), ("texture_u", "texture_v")]
        .into_iter()
        .find(|(u, v)| has(u) && has(v));
    let with_normals = has("nx") && has("ny") && has("nz");
    let mut normals = Vec::new();
    let mut uv = Vec::new();
    for (i, v) in vertices.iter().enumerate() {
        let get = |k: &str| -> Result<f64, String> {
            let x = v
                .get(k)
                .and_then(scalar)
                .ok_or_else(|| format!("vertex {i} has no number `{k}`"))?;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("vertex {i}: `{k}` is {x}"))
            }
        };
        mesh.positions
            .push(DVec3::new(get("x")?, get("y")?, get("z")?));
        if with_normals {
            normals.push(DVec3::new(get("nx")?, get("ny")?, get("nz")?));
        }
        if let Some((u, w)) = uv_keys {
            uv.push([get(u)?, get(w)?]);
        }
    }
    mesh.normals = with_normals.then_some(normals);
    mesh.uv = uv_keys.map(|_| uv);
    Ok(mesh)
}

fn face_indices(f: &DefaultElement) -> Result<Vec<usize>, String> {
    let list = f
        .get("vertex_indices")
        .or_else(|| f.get("vertex_index"))
        .ok_or("no `vertex_indices` list")?;
    let neg = || "a negative vertex index".to_string();
    let v: Vec<usize> = match list {
        Property::ListChar(l) => l
            .iter()
            .map(|&i| usize::try_from(i).map_err(|_| neg()))
            .collect::<Result<_, _>>()?,
        Property::ListUChar(l) => l.iter().map(|&i| usize::from(i)).collect(),
        Property::ListShort(l) => l
            .iter()
            .map(|&i| usize::try_from(i).map_err(|_| neg()))
            .collect::<Result<_, _>>()?,
        Property::ListUShort(l) => l.iter().map(|&i| usize::from(i)).collect(),
        Property::ListInt(l) => l
            .iter()
            .map(|&i| usize::try_from(i).map_err(|_| neg()))
            .collect::<Result<_, _>>()?,
        Property::ListUInt(l) => l.iter().map(|&i| i as usize).collect(),
        _ => return Err("`vertex_indices` is not a list of integers".into()),
    };
    Ok(v)
}

/// A PLY file's text from a mesh: the encoding named as in a header, for
/// tests and fixtures (`ascii`, `binary_little_endian`, `binary_big_endian`).
pub fn write_ply(mesh: &Mesh, encoding: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {encoding} 1.0\ncomment written by photonmap\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .into_bytes();
    let big = encoding == "binary_big_endian";
    let f = |out: &mut Vec<u8>, x: f32| {
        out.extend(if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        })
    };
    let i = |out: &mut Vec<u8>, x: i32| {
        out.extend(if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        })
    };
    for p in &mesh.positions {
        if encoding == "ascii" {
            out.extend(format!("{} {} {}\n", p.x as f32, p.y as f32, p.z as f32).bytes());
        } else {
            p.to_array().iter().for_each(|&c| f(&mut out, c as f32));
        }
    }
    for t in &mesh.triangles {
        if encoding == "ascii" {
            out.extend(format!("3 {} {} {}\n", t[0], t[1], t[2]).bytes());
        } else {
            out.push(3);
            t.iter().for_each(|&v| i(&mut out, v as i32));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn quad() -> Mesh {
        Mesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            ..Mesh::default()
        }
    }

    #[test]
    fn every_encoding_reads_back() {
        for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
            let m = parse_ply(&write_ply(&quad(), enc)).unwrap_or_else(|e| panic!("{enc}: {e:?}"));
            assert_eq!(m, quad(), "{enc}");
        }
    }

    #[test]
    fn polygons_fan_and_normals_and_uv_are_read() {
        let text = "ply\nformat ascii 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\nelement face 1\nproperty list uint uint vertex_index\nend_header\n0 0 0 0 0 1 0 0\n1 0 0 0 0 1 1 0\n1 1 0 0 0 1 1 1\n0 1 0 0 0 1 0 1\n4 0 1 2 3\n";
        let m = parse_ply(text.as_bytes()).unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(m.normals.unwrap()[3], DVec3::Z);
        assert_eq!(m.uv.unwrap()[2], [1.0, 1.0]);
    }

    #[test]
    fn bad_files_name_their_line() {
        let good = write_ply(&quad(), "ascii");
        let text = String::from_utf8(good)
            .unwrap()
            .replace("3 0 2 3", "3 0 2 9");
        let e = parse_ply(text.as_bytes()).unwrap_err();
        assert!(e.message.contains("vertex 9"), "{e:?}");
        let bin = write_ply(&quad(), "binary_little_endian");
        let e = parse_ply(&bin[..bin.len() - 5]).unwrap_err();
        assert_eq!(e.line, 10, "{e:?}");
        let e = parse_ply(
            b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nend_header\nzz\n",
        )
        .unwrap_err();
        assert_eq!(e.line, 6, "{e:?}");
    }
}
