//! TOML scene files (format in README.md) into `Scene`, with every error
//! naming the file, line and field.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use glam::Vec3;
use serde::Deserialize;
use toml::Spanned;

use super::{Camera, Geometry, Light, Material, PhotonMapParams, RenderParams, Scene, Shape};

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

// ---- the file as written -------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    name: Option<String>,
    camera: Spanned<CameraDef>,
    render: Option<Spanned<RenderDef>>,
    photon_map: Option<Spanned<PhotonMapDef>>,
    #[serde(default)]
    materials: BTreeMap<String, Spanned<MaterialDef>>,
    #[serde(default, rename = "shape")]
    shapes: Vec<Spanned<ShapeDef>>,
    #[serde(default, rename = "light")]
    lights: Vec<Spanned<LightDef>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraDef {
    position: [f32; 3],
    look_at: [f32; 3],
    up: Option<[f32; 3]>,
    vfov: f32,
    width: i64,
    height: i64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RenderDef {
    shadow_rays: Option<i64>,
    max_specular_depth: Option<i64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PhotonMapDef {
    photons_stored: Option<i64>,
    grid_resolution: Option<[i64; 3]>,
    grid_min: Option<[f32; 3]>,
    grid_max: Option<[f32; 3]>,
    k: Option<i64>,
    max_radius: Option<f32>,
    max_bounces: Option<i64>,
    store_direct: Option<bool>,
    caustics_only: Option<bool>,
    projection_resolution: Option<i64>,
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum MaterialDef {
    Diffuse { albedo: [f32; 3] },
    Mirror { reflectance: [f32; 3] },
    Glass { ior: f32 },
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum ShapeDef {
    Sphere {
        center: [f32; 3],
        radius: f32,
        material: String,
    },
    Cylinder {
        base: [f32; 3],
        axis: [f32; 3],
        radius: f32,
        height: f32,
        material: String,
    },
    Parallelogram {
        corner: [f32; 3],
        edge1: [f32; 3],
        edge2: [f32; 3],
        material: String,
    },
    Triangle {
        vertices: [[f32; 3]; 3],
        material: String,
    },
    Polygon {
        vertices: Vec<[f32; 3]>,
        material: String,
    },
    Mesh {
        file: String,
        material: String,
        #[serde(default = "one")]
        scale: f32,
        #[serde(default)]
        translate: [f32; 3],
    },
}

fn one() -> f32 {
    1.0
}

#[derive(Deserialize)]
#[serde(tag = "type", rename_all = "lowercase", deny_unknown_fields)]
enum LightDef {
    Area {
        corner: [f32; 3],
        edge1: [f32; 3],
        edge2: [f32; 3],
        normal: Option<[f32; 3]>,
        radiance: [f32; 3],
    },
    Point {
        position: [f32; 3],
        intensity: [f32; 3],
    },
}

// ---- defaults and limits ----------------------------------------------------

pub const MAX_IMAGE_SIDE: i64 = 16384;
pub const MAX_SHADOW_RAYS: i64 = 1024;
pub const MAX_SPECULAR_DEPTH: i64 = 64;
/// 2^24: float-addressed photon textures stay exact below it.
pub const MAX_PHOTONS_STORED: i64 = 1 << 24;
pub const MAX_GRID_SIDE: i64 = 512;
pub const MAX_K: i64 = 4096;
/// Explicit shapes plus mesh triangles the brute-force tracer loops over.
pub const MAX_PRIMITIVES: usize = 16384;

// ---- loading -------------------------------------------------------------------

pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|e| SceneError {
        file: path.to_path_buf(),
        line: 0,
        field: "(file)".into(),
        message: format!("cannot read the scene file: {e}"),
    })?;
    load_scene_str(&text, path)
}

/// Loads a scene from TOML text; `path` names it in errors and anchors OBJ paths.
pub fn load_scene_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
    let cx = Cx {
        text,
        file: path.to_path_buf(),
    };
    let file: SceneFile = toml::from_str(text).map_err(|e| cx.toml_error(&e))?;
    let base_dir = path.parent().unwrap_or(Path::new("."));

    // Camera.
    let cam = file.camera.get_ref();
    let cspan = file.camera.span();
    let position = cx.vec3(cspan.clone(), "camera.position", cam.position)?;
    let look_at = cx.vec3(cspan.clone(), "camera.look_at", cam.look_at)?;
    let up = cx.vec3(
        cspan.clone(),
        "camera.up",
        cam.up.unwrap_or([0.0, 1.0, 0.0]),
    )?;
    let vfov = cx.finite(cspan.clone(), "camera.vfov", cam.vfov)?;
    if !(vfov > 0.0 && vfov < 180.0) {
        return Err(cx.err(
            cspan,
            "camera.vfov",
            format!("{vfov} is outside the allowed range (0, 180) degrees"),
        ));
    }
    let width = cx.int_range(cspan.clone(), "camera.width", cam.width, 1, MAX_IMAGE_SIDE)?;
    let height = cx.int_range(
        cspan.clone(),
        "camera.height",
        cam.height,
        1,
        MAX_IMAGE_SIDE,
    )?;
    let view = look_at - position;
    if view.length() <= f32::EPSILON * position.abs().max_element().max(1.0) {
        return Err(cx.err(
            cspan,
            "camera.look_at",
            "equals camera.position: the view direction is undefined".into(),
        ));
    }
    if up.length() == 0.0 || view.normalize().cross(up.normalize()).length() < 1e-6 {
        return Err(cx.err(
            cspan,
            "camera.up",
            "is zero or parallel to the view direction".into(),
        ));
    }
    let camera = Camera {
        position,
        look_at,
        up,
        vfov_degrees: vfov,
        width: width as u32,
        height: height as u32,
    };

    // Render parameters.
    let render = match &file.render {
        None => RenderParams {
            shadow_rays: 1,
            max_specular_depth: 10,
        },
        Some(r) => {
            let s = r.span();
            let r = r.get_ref();
            RenderParams {
                shadow_rays: cx.int_range(
                    s.clone(),
                    "render.shadow_rays",
                    r.shadow_rays.unwrap_or(1),
                    1,
                    MAX_SHADOW_RAYS,
                )? as u32,
                max_specular_depth: cx.int_range(
                    s,
                    "render.max_specular_depth",
                    r.max_specular_depth.unwrap_or(10),
                    0,
                    MAX_SPECULAR_DEPTH,
                )? as u32,
            }
        }
    };

    // Materials by name.
    let mut materials = Vec::new();
    let mut material_index = BTreeMap::new();
    for (name, def) in &file.materials {
        let s = def.span();
        let f = |field: &str| format!("materials.{name}.{field}");
        let m = match def.get_ref() {
            MaterialDef::Diffuse { albedo } => Material::Diffuse {
                albedo: cx.unit_rgb(s.clone(), &f("albedo"), *albedo)?,
            },
            MaterialDef::Mirror { reflectance } => Material::Mirror {
                reflectance: cx.unit_rgb(s.clone(), &f("reflectance"), *reflectance)?,
            },
            MaterialDef::Glass { ior } => {
                let ior = cx.finite(s.clone(), &f("ior"), *ior)?;
                if !(1.0..=10.0).contains(&ior) {
                    return Err(cx.err(
                        s,
                        &f("ior"),
                        format!("{ior} is outside the allowed range [1, 10]"),
                    ));
                }
                Material::Glass { ior }
            }
        };
        material_index.insert(name.clone(), materials.len());
        materials.push(m);
    }

    // Shapes.
    let mut shapes = Vec::new();
    for (i, def) in file.shapes.iter().enumerate() {
        let s = def.span();
        let f = |field: &str| format!("shape[{i}].{field}");
        let material_of = |name: &str| -> Result<usize, SceneError> {
            material_index.get(name).copied().ok_or_else(|| {
                let known: Vec<_> = material_index.keys().cloned().collect();
                cx.err(
                    s.clone(),
                    &f("material"),
                    format!(
                        "no material named {name:?} (defined: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                )
            })
        };
        match def.get_ref() {
            ShapeDef::Sphere {
                center,
                radius,
                material,
            } => {
                let center = cx.vec3(s.clone(), &f("center"), *center)?;
                let radius = cx.positive(s.clone(), &f("radius"), *radius)?;
                shapes.push(Shape {
                    geometry: Geometry::Sphere { center, radius },
                    material: material_of(material)?,
                });
            }
            ShapeDef::Cylinder {
                base,
                axis,
                radius,
                height,
                material,
            } => {
                let base = cx.vec3(s.clone(), &f("base"), *base)?;
                let axis = cx.vec3(s.clone(), &f("axis"), *axis)?;
                if axis.length() == 0.0 {
                    return Err(cx.err(s, &f("axis"), "must not be the zero vector".into()));
                }
                let radius = cx.positive(s.clone(), &f("radius"), *radius)?;
                let height = cx.positive(s.clone(), &f("height"), *height)?;
                shapes.push(Shape {
                    geometry: Geometry::Cylinder {
                        base,
                        axis: axis.normalize(),
                        radius,
                        height,
                    },
                    material: material_of(material)?,
                });
            }
            ShapeDef::Parallelogram {
                corner,
                edge1,
                edge2,
                material,
            } => {
                let corner = cx.vec3(s.clone(), &f("corner"), *corner)?;
                let edge1 = cx.vec3(s.clone(), &f("edge1"), *edge1)?;
                let edge2 = cx.vec3(s.clone(), &f("edge2"), *edge2)?;
                cx.nondegenerate(s.clone(), &f("edge2"), edge1, edge2)?;
                shapes.push(Shape {
                    geometry: Geometry::Parallelogram {
                        corner,
                        edge1,
                        edge2,
                    },
                    material: material_of(material)?,
                });
            }
            ShapeDef::Triangle { vertices, material } => {
                let v: Vec<Vec3> = vertices
                    .iter()
                    .map(|v| cx.vec3(s.clone(), &f("vertices"), *v))
                    .collect::<Result<_, _>>()?;
                cx.nondegenerate(s.clone(), &f("vertices"), v[1] - v[0], v[2] - v[0])?;
                shapes.push(Shape {
                    geometry: Geometry::Triangle {
                        v0: v[0],
                        v1: v[1],
                        v2: v[2],
                    },
                    material: material_of(material)?,
                });
            }
            ShapeDef::Polygon { vertices, material } => {
                let m = material_of(material)?;
                let v: Vec<Vec3> = vertices
                    .iter()
                    .map(|v| cx.vec3(s.clone(), &f("vertices"), *v))
                    .collect::<Result<_, _>>()?;
                for t in triangulate_convex_polygon(&v)
                    .map_err(|msg| cx.err(s.clone(), &f("vertices"), msg))?
                {
                    shapes.push(Shape {
                        geometry: t,
                        material: m,
                    });
                }
            }
            ShapeDef::Mesh {
                file: obj,
                material,
                scale,
                translate,
            } => {
                let m = material_of(material)?;
                let scale = cx.positive(s.clone(), &f("scale"), *scale)?;
                let translate = cx.vec3(s.clone(), &f("translate"), *translate)?;
                let obj_path = base_dir.join(obj);
                let tris = load_obj(&obj_path).map_err(|msg| cx.err(s.clone(), &f("file"), msg))?;
                for [a, b, c] in tris {
                    let [v0, v1, v2] = [a, b, c].map(|p| p * scale + translate);
                    shapes.push(Shape {
                        geometry: Geometry::Triangle { v0, v1, v2 },
                        material: m,
                    });
                }
            }
        }
    }

    // Lights (area lights are also shapes: the camera sees them).
    let mut lights = Vec::new();
    for (i, def) in file.lights.iter().enumerate() {
        let s = def.span();
        let f = |field: &str| format!("light[{i}].{field}");
        match def.get_ref() {
            LightDef::Area {
                corner,
                edge1,
                edge2,
                normal,
                radiance,
            } => {
                let corner = cx.vec3(s.clone(), &f("corner"), *corner)?;
                let edge1 = cx.vec3(s.clone(), &f("edge1"), *edge1)?;
                let edge2 = cx.vec3(s.clone(), &f("edge2"), *edge2)?;
                cx.nondegenerate(s.clone(), &f("edge2"), edge1, edge2)?;
                let geometric = edge1.cross(edge2).normalize();
                let normal = match normal {
                    None => geometric,
                    Some(n) => {
                        let n = cx.vec3(s.clone(), &f("normal"), *n)?;
                        if n.length() == 0.0 {
                            return Err(cx.err(
                                s,
                                &f("normal"),
                                "must not be the zero vector".into(),
                            ));
                        }
                        let n = n.normalize();
                        if n.dot(geometric).abs() < 1.0 - 1e-5 {
                            return Err(cx.err(s, &f("normal"), format!("{:?} is not perpendicular to the light's plane (edge1 x edge2 gives {:?})", n.to_array(), geometric.to_array())));
                        }
                        n
                    }
                };
                let radiance = cx.nonnegative_rgb(s.clone(), &f("radiance"), *radiance)?;
                let m = materials.len();
                materials.push(Material::Emitter { radiance, normal });
                shapes.push(Shape {
                    geometry: Geometry::Parallelogram {
                        corner,
                        edge1,
                        edge2,
                    },
                    material: m,
                });
                lights.push(Light::Area {
                    corner,
                    edge1,
                    edge2,
                    normal,
                    radiance,
                });
            }
            LightDef::Point {
                position,
                intensity,
            } => {
                let position = cx.vec3(s.clone(), &f("position"), *position)?;
                let intensity = cx.nonnegative_rgb(s.clone(), &f("intensity"), *intensity)?;
                lights.push(Light::Point {
                    position,
                    intensity,
                });
            }
        }
    }
    if lights.is_empty() {
        return Err(SceneError {
            file: cx.file.clone(),
            line: 1,
            field: "light".into(),
            message: "the scene has no [[light]]: nothing would be lit".into(),
        });
    }
    if shapes.len() > MAX_PRIMITIVES {
        return Err(SceneError { file: cx.file.clone(), line: 1, field: "shape".into(), message: format!("{} primitives (mesh triangles included); at most {MAX_PRIMITIVES} are supported until an acceleration structure exists", shapes.len()) });
    }

    // Photon-map parameters.
    let photon_map = {
        let (s, p) = match &file.photon_map {
            Some(p) => (p.span(), Some(p.get_ref())),
            None => (0..0, None),
        };
        let photons_stored = p.and_then(|p| p.photons_stored).unwrap_or(10_000);
        let res = p.and_then(|p| p.grid_resolution).unwrap_or([64, 64, 64]);
        let mut grid_resolution = [0u32; 3];
        for a in 0..3 {
            grid_resolution[a] = cx.int_range(
                s.clone(),
                "photon_map.grid_resolution",
                res[a],
                1,
                MAX_GRID_SIDE,
            )? as u32;
        }
        let grid_bounds = match (p.and_then(|p| p.grid_min), p.and_then(|p| p.grid_max)) {
            (None, None) => None,
            (Some(lo), Some(hi)) => {
                let lo = cx.vec3(s.clone(), "photon_map.grid_min", lo)?;
                let hi = cx.vec3(s.clone(), "photon_map.grid_max", hi)?;
                if !(lo.cmplt(hi).all()) {
                    return Err(cx.err(
                        s,
                        "photon_map.grid_max",
                        format!(
                            "{:?} must exceed grid_min {:?} on every axis",
                            hi.to_array(),
                            lo.to_array()
                        ),
                    ));
                }
                Some((lo, hi))
            }
            (Some(_), None) => {
                return Err(cx.err(
                    s,
                    "photon_map.grid_max",
                    "missing: grid_min and grid_max go together".into(),
                ))
            }
            (None, Some(_)) => {
                return Err(cx.err(
                    s,
                    "photon_map.grid_min",
                    "missing: grid_min and grid_max go together".into(),
                ))
            }
        };
        let store_direct = p.and_then(|p| p.store_direct).unwrap_or(false);
        let caustics_only = p.and_then(|p| p.caustics_only).unwrap_or(false);
        if store_direct && caustics_only {
            return Err(cx.err(
                s,
                "photon_map.caustics_only",
                "caustics_only and store_direct exclude each other: a caustic photon is never stored at its first hit".into(),
            ));
        }
        if caustics_only && !shapes.iter().any(|x| materials[x.material].is_specular()) {
            return Err(cx.err(
                s,
                "photon_map.caustics_only",
                "no shape is mirror or glass, so the scene has no caustics to store".into(),
            ));
        }
        let max_radius = cx.positive(
            s.clone(),
            "photon_map.max_radius",
            p.and_then(|p| p.max_radius)
                .unwrap_or(0.1 * scene_size(&shapes)),
        )?;
        PhotonMapParams {
            photons_stored: cx.int_range(
                s.clone(),
                "photon_map.photons_stored",
                photons_stored,
                1,
                MAX_PHOTONS_STORED,
            )? as u32,
            grid_resolution,
            grid_bounds,
            k: cx.int_range(
                s.clone(),
                "photon_map.k",
                p.and_then(|p| p.k).unwrap_or(50),
                1,
                MAX_K,
            )? as u32,
            max_radius,
            max_bounces: cx.int_range(
                s.clone(),
                "photon_map.max_bounces",
                p.and_then(|p| p.max_bounces).unwrap_or(8),
                1,
                64,
            )? as u32,
            store_direct,
            caustics_only,
            projection_resolution: cx.int_range(
                s,
                "photon_map.projection_resolution",
                p.and_then(|p| p.projection_resolution)
                    .unwrap_or(crate::photon::projection::DEFAULT_RESOLUTION as i64),
                crate::photon::projection::MIN_RESOLUTION as i64,
                crate::photon::projection::MAX_RESOLUTION as i64,
            )? as u32,
        }
    };

    let name = file.name.clone().unwrap_or_else(|| {
        path.file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default()
    });
    Ok(Scene {
        name,
        camera,
        materials,
        shapes,
        lights,
        render,
        photon_map,
    })
}

fn scene_size(shapes: &[Shape]) -> f32 {
    Scene::with_shapes(shapes.to_vec(), vec![], vec![]).size()
}

/// Splits a planar convex polygon into a triangle fan.
fn triangulate_convex_polygon(v: &[Vec3]) -> Result<Vec<Geometry>, String> {
    if v.len() < 3 {
        return Err(format!(
            "a polygon needs at least 3 vertices, got {}",
            v.len()
        ));
    }
    let mut normal = Vec3::ZERO; // Newell's method: robust for any planar polygon
    for i in 0..v.len() {
        let (a, b) = (v[i], v[(i + 1) % v.len()]);
        normal += Vec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        );
    }
    let size = v.iter().fold(0f32, |m, p| m.max((*p - v[0]).length()));
    if normal.length() <= 1e-12 * size * size || size == 0.0 {
        return Err("the polygon is degenerate (zero area)".into());
    }
    let n = normal.normalize();
    for (i, p) in v.iter().enumerate() {
        let off = (*p - v[0]).dot(n).abs();
        if off > 1e-5 * size {
            return Err(format!(
                "vertex {i} lies {off} off the polygon's plane: polygons must be planar"
            ));
        }
    }
    for i in 0..v.len() {
        let (a, b, c) = (v[i], v[(i + 1) % v.len()], v[(i + 2) % v.len()]);
        if (b - a).cross(c - b).dot(n) < -1e-6 * size * size {
            return Err(format!(
                "the polygon is not convex at vertex {}",
                (i + 1) % v.len()
            ));
        }
    }
    Ok((1..v.len() - 1)
        .map(|i| Geometry::Triangle {
            v0: v[0],
            v1: v[i],
            v2: v[i + 1],
        })
        .collect())
}

/// Loads an OBJ file's triangles, refusing non-finite or absurd coordinates.
fn load_obj(path: &Path) -> Result<Vec<[Vec3; 3]>, String> {
    if !path.is_file() {
        return Err(format!(
            "cannot read OBJ file {}: no such file",
            path.display()
        ));
    }
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| format!("cannot read OBJ file {}: {e}", path.display()))?;
    let mut tris = Vec::new();
    for model in &models {
        let m = &model.mesh;
        for (i, &p) in m.positions.iter().enumerate() {
            if !p.is_finite() || p.abs() > 1e30 {
                return Err(format!("OBJ file {}: vertex {} of object {:?} has coordinate {p}: coordinates must be finite", path.display(), i / 3 + 1, model.name));
            }
        }
        let vertex = |i: u32| -> Result<Vec3, String> {
            let i = i as usize * 3;
            m.positions
                .get(i..i + 3)
                .map(Vec3::from_slice)
                .ok_or_else(|| {
                    format!(
                        "OBJ file {}: a face refers to a missing vertex",
                        path.display()
                    )
                })
        };
        for f in m.indices.chunks(3) {
            if f.len() == 3 {
                tris.push([vertex(f[0])?, vertex(f[1])?, vertex(f[2])?]);
            }
        }
    }
    if tris.is_empty() {
        return Err(format!("OBJ file {} holds no triangles", path.display()));
    }
    Ok(tris)
}

// ---- error plumbing ------------------------------------------------------------

struct Cx<'a> {
    text: &'a str,
    file: PathBuf,
}

impl Cx<'_> {
    fn line_of(&self, offset: usize) -> usize {
        self.text[..offset.min(self.text.len())]
            .matches('\n')
            .count()
            + 1
    }

    /// The line of `key =` in a table: from the table's span (for `[header]`
    /// tables the span holds only the header) up to the next header.
    fn field_line(&self, span: std::ops::Range<usize>, field: &str) -> usize {
        let key = field.rsplit('.').next().unwrap_or(field);
        let key = key.split('[').next().unwrap_or(key);
        let start = span.start.min(self.text.len());
        let inline = self.text[start..].starts_with('{');
        let end = if inline {
            span.end.min(self.text.len())
        } else {
            self.text.len()
        };
        let mut offset = start;
        for (n, line) in self.text[start..end].split_inclusive('\n').enumerate() {
            let trimmed = line.trim_start();
            let is_header = trimmed.starts_with('[')
                && trimmed
                    .trim_start_matches('[')
                    .starts_with(|c: char| c.is_alphabetic() || c == '"');
            if n > 0 && is_header && !inline {
                break;
            }
            let mut rest = trimmed;
            // Also inside an inline table: `{ a = 1, key = 2 }`.
            loop {
                if let Some(after) = rest.strip_prefix(key) {
                    if after.trim_start().starts_with('=') {
                        return self.line_of(offset);
                    }
                }
                match rest.find([',', '{']) {
                    Some(i) => rest = rest[i + 1..].trim_start(),
                    None => break,
                }
            }
            offset += line.len();
        }
        self.line_of(span.start)
    }

    fn err(&self, span: std::ops::Range<usize>, field: &str, message: String) -> SceneError {
        SceneError {
            file: self.file.clone(),
            line: self.field_line(span, field),
            field: field.to_string(),
            message,
        }
    }

    fn toml_error(&self, e: &toml::de::Error) -> SceneError {
        let span = e.span().unwrap_or(0..0);
        let message = e.message().trim().to_string();
        let named = |what: &str| {
            message
                .contains(what)
                .then(|| message.split('`').nth(1).map(str::to_string))
                .flatten()
        };
        // serde names the field in backticks: "unknown field `radiu`", "missing field `radius`".
        if let Some(field) = named("unknown field") {
            let line = self.field_line(span, &field);
            return SceneError {
                file: self.file.clone(),
                line,
                field,
                message,
            };
        }
        if let Some(field) = named("missing field") {
            return SceneError {
                file: self.file.clone(),
                line: self.line_of(span.start),
                field,
                message,
            };
        }
        if message.starts_with("unknown variant") {
            let line = self.field_line(span, "type");
            return SceneError {
                file: self.file.clone(),
                line,
                field: "type".into(),
                message,
            };
        }
        // A type error inside a tagged table is reported at the table: find the
        // line whose value is the one the message quotes.
        if let Some((line, key)) = self.line_with_value(span.clone(), &message) {
            return SceneError {
                file: self.file.clone(),
                line,
                field: key,
                message,
            };
        }
        let field = self
            .key_before(span.start)
            .unwrap_or_else(|| "(syntax)".into());
        SceneError {
            file: self.file.clone(),
            line: self.line_of(span.start),
            field,
            message,
        }
    }

    /// For "invalid type: string \"big\", expected f32", the `key = "big"` line.
    fn line_with_value(
        &self,
        span: std::ops::Range<usize>,
        message: &str,
    ) -> Option<(usize, String)> {
        let rest = message
            .strip_prefix("invalid type: ")
            .or_else(|| message.strip_prefix("invalid value: "))?;
        let value = rest
            .split(", expected")
            .next()?
            .split_once(' ')?
            .1
            .trim()
            .trim_matches('`');
        let start = span.start.min(self.text.len());
        let mut offset = start;
        for line in self.text[start..].split_inclusive('\n') {
            if let Some((key, v)) = line.split_once('=') {
                if v.trim().starts_with(value) && !value.is_empty() {
                    let key = key.rsplit([',', '{']).next().unwrap_or(key).trim();
                    return Some((self.line_of(offset), key.to_string()));
                }
            }
            offset += line.len();
        }
        None
    }

    /// For a type error at a value, the key on the same line (`radius = "x"` -> radius).
    fn key_before(&self, offset: usize) -> Option<String> {
        let start = self.text[..offset.min(self.text.len())]
            .rfind('\n')
            .map_or(0, |i| i + 1);
        let line = &self.text[start..offset.min(self.text.len())];
        let key = line.rsplit_once('=')?.0.rsplit([',', '{']).next()?.trim();
        (!key.is_empty()).then(|| key.to_string())
    }

    fn finite(&self, s: std::ops::Range<usize>, field: &str, v: f32) -> Result<f32, SceneError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(s, field, format!("{v} is not a finite number")))
        }
    }

    fn vec3(
        &self,
        s: std::ops::Range<usize>,
        field: &str,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        for x in v {
            self.finite(s.clone(), field, x)?;
        }
        let v = Vec3::from(v);
        if v.abs().max_element() > 1e15 {
            return Err(self.err(
                s,
                field,
                format!(
                    "{:?} is too large: coordinates must stay within 1e15",
                    v.to_array()
                ),
            ));
        }
        Ok(v)
    }

    fn positive(&self, s: std::ops::Range<usize>, field: &str, v: f32) -> Result<f32, SceneError> {
        let v = self.finite(s.clone(), field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(s, field, format!("{v} must be greater than 0")))
        }
    }

    fn unit_rgb(
        &self,
        s: std::ops::Range<usize>,
        field: &str,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        let c = self.vec3(s.clone(), field, v)?;
        if c.min_element() < 0.0 || c.max_element() > 1.0 {
            return Err(self.err(
                s,
                field,
                format!("{v:?}: each channel must be in [0, 1] (energy conservation)"),
            ));
        }
        Ok(c)
    }

    fn nonnegative_rgb(
        &self,
        s: std::ops::Range<usize>,
        field: &str,
        v: [f32; 3],
    ) -> Result<Vec3, SceneError> {
        let c = self.vec3(s.clone(), field, v)?;
        if c.min_element() < 0.0 {
            return Err(self.err(s, field, format!("{v:?}: each channel must be >= 0")));
        }
        Ok(c)
    }

    fn int_range(
        &self,
        s: std::ops::Range<usize>,
        field: &str,
        v: i64,
        lo: i64,
        hi: i64,
    ) -> Result<i64, SceneError> {
        if (lo..=hi).contains(&v) {
            Ok(v)
        } else {
            Err(self.err(
                s,
                field,
                format!("{v} is outside the allowed range {lo}..={hi}"),
            ))
        }
    }

    fn nondegenerate(
        &self,
        s: std::ops::Range<usize>,
        field: &str,
        a: Vec3,
        b: Vec3,
    ) -> Result<(), SceneError> {
        let scale = a.length() * b.length();
        if scale == 0.0 || a.cross(b).length() <= 1e-7 * scale {
            return Err(self.err(
                s,
                field,
                "the edges are zero or parallel: the shape has no area".into(),
            ));
        }
        Ok(())
    }
}
