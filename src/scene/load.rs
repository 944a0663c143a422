//! TOML scene files (format in README.md) into `Scene`, with every error
//! naming the file, line and field.
//!
//! The text is parsed with toml's span-keeping document API (`DeTable`), in
//! which every key and value keeps its byte span. Overrides (`key.path=value`,
//! see `load_scene_str_with_overrides`) are spliced into that document before
//! anything is read, so they are validated exactly like the file. Then each
//! section is read by its own function (camera, render, photon_map, materials,
//! shapes, lights) through `Table`, which takes every error's place from the
//! span of what it is about:
//!
//! - an unknown field: the unknown key's line;
//! - a missing field: the table's header line (or the inline table's line);
//! - a wrong type: the value's line (the element's, inside an array);
//! - an unknown `type`: the `type = ...` line;
//! - a value out of range: the value's line, or the table's header line when
//!   the value is a default (`defaults`) that does not fit.
//!
//! Errors about the shape of the document (unknown, missing, mistyped fields,
//! unknown types) name the key as written in `field` and the full path in
//! their message; validation errors name the full path (`shape[6].radius`).
//!
//! Points are read in f64 and rebased (`rebase`): before the sections are
//! read, a pre-pass over the document finds the scene's local origin O (the
//! centre of its points' box, or the camera), and every point p is then
//! stored as the f32 of p - O. Directions, edges, radii and colours are read
//! as f32, as before. `load_scene_str_translated` moves every point by a
//! vector in f64 first: a file whose coordinates are moved, without its
//! text being edited.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DVec3, Vec3};
use serde::de::value::SeqDeserializer;
use serde::de::{DeserializeOwned, IntoDeserializer};
use serde::Deserialize;
use toml::de::{DeString, DeTable, DeValue, ValueDeserializer};
use toml::Spanned;

use super::defaults::{
    default_max_radius, DEFAULT_UP, IOR_RANGE, MAX_BOUNCES, MAX_COORDINATE,
    MAX_PROJECTION_RESOLUTION, MIN_PROJECTION_RESOLUTION, VFOV_RANGE,
};
pub use super::defaults::{
    MAX_GRID_SIDE, MAX_IMAGE_SIDE, MAX_K, MAX_PHOTONS_STORED, MAX_SHADOW_RAYS, MAX_SPECULAR_DEPTH,
};
use super::rebase::{self, dvec3, Coord, Rebase};
use super::{Camera, Geometry, Light, Material, PhotonMapParams, RenderParams, Scene, Shape};

mod mesh;

pub use crate::error::SceneError;

type Span = Range<usize>;
type Value<'a> = Spanned<DeValue<'a>>;

// ---- the format's tables and their fields ---------------------------------

const TOP_LEVEL: &[&str] = &[
    "name",
    "camera",
    "render",
    "photon_map",
    "materials",
    "shape",
    "light",
];
const CAMERA: &[&str] = &["position", "look_at", "up", "vfov", "width", "height"];
const RENDER: &[&str] = &["shadow_rays", "max_specular_depth"];
const PHOTON_MAP: &[&str] = &[
    "photons_stored",
    "grid_resolution",
    "grid_min",
    "grid_max",
    "k",
    "max_radius",
    "max_bounces",
    "store_direct",
    "caustics_only",
    "projection_resolution",
];

/// A tagged table's kinds: the `type` value, the kind, and its other fields.
type Kinds<K> = [(&'static str, K, &'static [&'static str])];

#[derive(Clone, Copy)]
enum MaterialKind {
    Diffuse,
    Mirror,
    Glass,
}

const MATERIAL_KINDS: &Kinds<MaterialKind> = &[
    ("diffuse", MaterialKind::Diffuse, &["albedo"]),
    ("mirror", MaterialKind::Mirror, &["reflectance"]),
    ("glass", MaterialKind::Glass, &["ior"]),
];

#[derive(Clone, Copy)]
enum ShapeKind {
    Sphere,
    Cylinder,
    Parallelogram,
    Triangle,
    Polygon,
    Mesh,
}

const SHAPE_KINDS: &Kinds<ShapeKind> = &[
    (
        "sphere",
        ShapeKind::Sphere,
        &["center", "radius", "material"],
    ),
    (
        "cylinder",
        ShapeKind::Cylinder,
        &["base", "axis", "radius", "height", "material"],
    ),
    (
        "parallelogram",
        ShapeKind::Parallelogram,
        &["corner", "edge1", "edge2", "material"],
    ),
    ("triangle", ShapeKind::Triangle, &["vertices", "material"]),
    ("polygon", ShapeKind::Polygon, &["vertices", "material"]),
    (
        "mesh",
        ShapeKind::Mesh,
        &["file", "material", "scale", "translate", "object_materials"],
    ),
];

#[derive(Clone, Copy)]
enum LightKind {
    Area,
    Point,
}

const LIGHT_KINDS: &Kinds<LightKind> = &[
    (
        "area",
        LightKind::Area,
        &["corner", "edge1", "edge2", "normal", "radiance"],
    ),
    ("point", LightKind::Point, &["position", "intensity"]),
];

// ---- loading -------------------------------------------------------------------

pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = super::file::read_stable(path).map_err(|e| {
        SceneError::new(
            path,
            0,
            "(file)",
            format!("cannot read the scene file: {e}"),
        )
    })?;
    load_scene_str(&text, path)
}

/// Loads a scene from TOML text; `path` names it in errors and anchors OBJ paths.
pub fn load_scene_str(text: &str, path: &Path) -> Result<Scene, SceneError> {
    load_scene_str_with_overrides(text, path, &[])
}

/// Loads a scene from TOML text with `overrides` applied, in order, before
/// anything is validated: pairs of a key path and a TOML value, such as
/// `("photon_map.k", "64")`, `("camera.width", "256")`,
/// `("shape[1].radius", "0.5")` or
/// `("materials.gold", "{ type = \"glass\", ior = 1.5 }")`.
///
/// A path's segments are keys, each with an optional 0-based `[index]` into
/// an array of tables; missing tables on the way are created, and an index
/// one past the end appends (`light[1] = { ... }` to a scene with one
/// light). An overridden value is checked exactly like one in the file, and
/// every error about it names the override as its file, e.g.
/// `--set shape[1].radius:1: shape[1].radius: -1 must be greater than 0`.
pub fn load_scene_str_with_overrides(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
) -> Result<Scene, SceneError> {
    load_scene_document(text, path, overrides, DVec3::ZERO, Rebase::SceneCentre)
}

/// Loads a scene from TOML text as if every point in it (camera position and
/// target, centres, bases, corners, vertices, mesh placements, point lights,
/// grid bounds) were moved by `t`: each is read in f64, `t` is added in
/// f64, and the scene is rebased as `rebase` says. So "the file moved by
/// 1e6" needs no edited text (the stress suite and tests use this).
pub fn load_scene_str_translated(
    text: &str,
    path: &Path,
    t: DVec3,
    rebase: Rebase,
) -> Result<Scene, SceneError> {
    load_scene_document(text, path, &[], t, rebase)
}

/// Parses, applies the overrides, finds the local origin, reads the sections.
fn load_scene_document(
    text: &str,
    path: &Path,
    overrides: &[(String, String)],
    t: DVec3,
    rebase: Rebase,
) -> Result<Scene, SceneError> {
    let mut cx = Cx::new(text, path, overrides);
    let mut root = DeTable::parse(text)
        .map_err(|e| cx.syntax_error(&e))?
        .into_inner();
    for o in &cx.overrides {
        cx.apply_override(&mut root, o)?;
    }
    cx.translate = t;
    cx.origin = local_origin(&root, t, rebase);
    read_scene(&cx, &root)
}

/// Where each section keeps its points.
const POINTS: &[(&str, &[&str])] = &[
    ("camera", &["position", "look_at"]),
    ("photon_map", &["grid_min", "grid_max"]),
    (
        "shape",
        &["center", "base", "corner", "vertices", "translate"],
    ),
    ("light", &["corner", "position"]),
];

/// The pre-pass: the local origin of the document's points, each moved by
/// `t`. It refuses nothing: whatever is not a finite point within
/// MAX_COORDINATE is left out here and refused, in its place, by the reading
/// that follows.
fn local_origin(root: &DeTable, t: DVec3, rebase: Rebase) -> DVec3 {
    let points_of = |value: &Value| -> Vec<DVec3> {
        let many = match <[Coord; 3]>::deserialize(Strict(value.clone())) {
            Ok(p) => vec![p],
            Err(_) => Vec::<[Coord; 3]>::deserialize(Strict(value.clone())).unwrap_or_default(),
        };
        many.into_iter()
            .map(|p| dvec3(p) + t)
            .filter(|p| p.is_finite() && p.abs().max_element() <= f64::from(MAX_COORDINATE))
            .collect()
    };
    let tables = |section: &str| -> Vec<&DeTable> {
        match root.get(section).map(Spanned::get_ref) {
            Some(DeValue::Table(t)) => vec![t],
            Some(DeValue::Array(items)) => items
                .iter()
                .filter_map(|i| match i.get_ref() {
                    DeValue::Table(t) => Some(t),
                    _ => None,
                })
                .collect(),
            _ => Vec::new(),
        }
    };
    let mut points = Vec::new();
    for (section, keys) in POINTS {
        for table in tables(section) {
            for key in *keys {
                points.extend(table.get(*key).map(points_of).unwrap_or_default());
            }
        }
    }
    let camera = tables("camera")
        .first()
        .and_then(|c| c.get("position"))
        .map(points_of)
        .and_then(|p| p.first().copied());
    rebase::origin(&points, camera, rebase)
}

/// The whole document, section by section.
fn read_scene(cx: &Cx, root: &DeTable) -> Result<Scene, SceneError> {
    let doc = Table {
        cx,
        path: String::new(),
        span: 0..0,
        map: root,
    };
    doc.only(TOP_LEVEL, false)?;
    let absent = DeTable::new();
    let name = doc.get::<String>("name")?.map(Spanned::into_inner);
    let camera = read_camera(&doc.table("camera", None)?)?;
    let render = read_render(&doc.table("render", Some(&absent))?)?;
    let photon_map = read_photon_map(&doc.table("photon_map", Some(&absent))?)?;
    let (materials, names) = read_materials(&doc.table("materials", Some(&absent))?)?;
    let mut model = Model {
        materials,
        names,
        shapes: Vec::new(),
        lights: Vec::new(),
    };
    for t in doc.array("shape")? {
        read_shape(&t, &mut model)?;
    }
    let Model {
        mut materials,
        mut shapes,
        mut lights,
        ..
    } = model;
    for t in doc.array("light")? {
        lights.push(read_light(&t, &mut materials, &mut shapes)?);
    }
    if lights.is_empty() {
        return Err(cx.err(
            0..0,
            "light",
            "the scene has no [[light]] and no emissive mesh material: nothing would be lit".into(),
        ));
    }
    let photon_map = photon_map.finish(cx, &shapes, &materials)?;
    let name = name.unwrap_or_else(|| {
        cx.file
            .file_stem()
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
        origin: cx.origin,
    })
}

// ---- the sections ----------------------------------------------------------------

fn read_camera(t: &Table) -> Result<Camera, SceneError> {
    t.only(CAMERA, false)?;
    let position = t.point("position")?;
    let look_at_at = t.req::<[Coord; 3]>("look_at")?;
    let look_at = t.cx.local(t.check_point("look_at", &look_at_at)?);
    let up_at = t.or("up", DEFAULT_UP.to_array())?;
    let up = t.check_vec3("up", &up_at)?;
    let vfov_at = t.req::<f32>("vfov")?;
    let vfov =
        t.cx.finite(vfov_at.span(), &t.field("vfov"), *vfov_at.get_ref())?;
    let (lo, hi) = VFOV_RANGE;
    if !(vfov > lo && vfov < hi) {
        return Err(t.cx.err(
            vfov_at.span(),
            &t.field("vfov"),
            format!("{vfov} is outside the allowed range ({lo}, {hi}) degrees"),
        ));
    }
    let width = t.int("width", None, 1, MAX_IMAGE_SIDE)?;
    let height = t.int("height", None, 1, MAX_IMAGE_SIDE)?;
    let view = look_at - position;
    if view.length() <= f32::EPSILON * position.abs().max_element().max(1.0) {
        return Err(t.cx.err(
            look_at_at.span(),
            &t.field("look_at"),
            "equals camera.position: the view direction is undefined".into(),
        ));
    }
    if up.length() == 0.0 || view.normalize().cross(up.normalize()).length() < 1e-6 {
        return Err(t.cx.err(
            up_at.span(),
            &t.field("up"),
            "is zero or parallel to the view direction".into(),
        ));
    }
    Ok(Camera {
        position,
        look_at,
        up,
        vfov_degrees: vfov,
        width,
        height,
    })
}

fn read_render(t: &Table) -> Result<RenderParams, SceneError> {
    t.only(RENDER, false)?;
    let d = RenderParams::default();
    Ok(RenderParams {
        shadow_rays: t.int("shadow_rays", Some(d.shadow_rays), 1, MAX_SHADOW_RAYS)?,
        max_specular_depth: t.int(
            "max_specular_depth",
            Some(d.max_specular_depth),
            0,
            MAX_SPECULAR_DEPTH,
        )?,
    })
}

/// `[photon_map]` as read, before the checks that need the shapes.
struct PhotonMapDraft {
    params: PhotonMapParams,
    /// The table's span: where a default that does not fit is reported.
    table: Span,
    max_radius: Option<f32>,
    caustics_only_at: Span,
}

fn read_photon_map(t: &Table) -> Result<PhotonMapDraft, SceneError> {
    t.only(PHOTON_MAP, false)?;
    let d = PhotonMapParams::defaults_for(&[]);
    let photons_stored = t.int(
        "photons_stored",
        Some(d.photons_stored),
        1,
        MAX_PHOTONS_STORED,
    )?;
    let res = t.or("grid_resolution", d.grid_resolution.map(i64::from))?;
    let mut grid_resolution = [0u32; 3];
    for (cells, &asked) in grid_resolution.iter_mut().zip(res.get_ref()) {
        let field = t.field("grid_resolution");
        *cells =
            t.cx.int_range(res.span(), &field, asked, 1, MAX_GRID_SIDE)? as u32;
    }
    let grid_bounds = read_grid_bounds(t)?;
    let k = t.int("k", Some(d.k), 1, MAX_K)?;
    let max_radius = match t.get::<f32>("max_radius")? {
        Some(r) => Some(t.cx.positive(r.span(), &t.field("max_radius"), *r.get_ref())?),
        None => None,
    };
    let max_bounces = t.int("max_bounces", Some(d.max_bounces), 1, MAX_BOUNCES)?;
    let store_direct = t.or("store_direct", d.store_direct)?;
    let caustics_only = t.or("caustics_only", d.caustics_only)?;
    if *store_direct.get_ref() && *caustics_only.get_ref() {
        return Err(t.cx.err(
            caustics_only.span(),
            &t.field("caustics_only"),
            "caustics_only and store_direct exclude each other: a caustic photon is never stored at its first hit".into(),
        ));
    }
    let projection_resolution = t.int(
        "projection_resolution",
        Some(d.projection_resolution),
        MIN_PROJECTION_RESOLUTION as i64,
        MAX_PROJECTION_RESOLUTION as i64,
    )?;
    Ok(PhotonMapDraft {
        params: PhotonMapParams {
            photons_stored,
            grid_resolution,
            grid_bounds,
            k,
            max_radius: d.max_radius,
            max_bounces,
            store_direct: store_direct.into_inner(),
            caustics_only: *caustics_only.get_ref(),
            projection_resolution,
        },
        table: t.span.clone(),
        max_radius,
        caustics_only_at: caustics_only.span(),
    })
}

/// `grid_min` and `grid_max`: both or neither.
fn read_grid_bounds(t: &Table) -> Result<Option<(Vec3, Vec3)>, SceneError> {
    let missing = |field: &str| {
        t.cx.err(
            t.span.clone(),
            &t.field(field),
            "missing: grid_min and grid_max go together".into(),
        )
    };
    match (
        t.get::<[Coord; 3]>("grid_min")?,
        t.get::<[Coord; 3]>("grid_max")?,
    ) {
        (None, None) => Ok(None),
        (Some(_), None) => Err(missing("grid_max")),
        (None, Some(_)) => Err(missing("grid_min")),
        (Some(lo_at), Some(hi_at)) => {
            let lo = t.check_point("grid_min", &lo_at)?;
            let hi = t.check_point("grid_max", &hi_at)?;
            let (lo_local, hi_local) = (t.cx.local(lo), t.cx.local(hi));
            // In the file's frame, and in f32 where the grid is used.
            if !(lo.cmplt(hi).all() && lo_local.cmplt(hi_local).all()) {
                return Err(t.cx.err(
                    hi_at.span(),
                    &t.field("grid_max"),
                    format!(
                        "{:?} must exceed grid_min {:?} on every axis",
                        hi.to_array(),
                        lo.to_array()
                    ),
                ));
            }
            Ok(Some((lo_local, hi_local)))
        }
    }
}

impl PhotonMapDraft {
    /// The checks and defaults that depend on the scene's shapes.
    fn finish(
        self,
        cx: &Cx,
        shapes: &[Shape],
        materials: &[Material],
    ) -> Result<PhotonMapParams, SceneError> {
        let mut params = self.params;
        if params.caustics_only && !shapes.iter().any(|x| materials[x.material].is_specular()) {
            return Err(cx.err(
                self.caustics_only_at,
                "photon_map.caustics_only",
                "no shape is mirror or glass, so the scene has no caustics to store".into(),
            ));
        }
        params.max_radius = match self.max_radius {
            Some(r) => r,
            None => cx.positive(
                self.table,
                "photon_map.max_radius",
                default_max_radius(shapes),
            )?,
        };
        Ok(params)
    }
}

/// Materials in name order (their indices are the order of names), and the
/// index of each name.
fn read_materials(t: &Table) -> Result<(Vec<Material>, BTreeMap<String, usize>), SceneError> {
    let mut entries: Vec<_> = t.map.iter().collect();
    entries.sort_by(|a, b| a.0.get_ref().cmp(b.0.get_ref()));
    let mut materials = Vec::new();
    let mut index = BTreeMap::new();
    for (name, value) in entries {
        let m = Table::new(t.cx, t.field(name.get_ref()), name.get_ref(), value)?;
        index.insert(name.get_ref().to_string(), materials.len());
        materials.push(read_material(&m)?);
    }
    Ok((materials, index))
}

fn read_material(t: &Table) -> Result<Material, SceneError> {
    Ok(match t.kind(MATERIAL_KINDS)? {
        MaterialKind::Diffuse => Material::Diffuse {
            albedo: t.unit_rgb("albedo")?,
        },
        MaterialKind::Mirror => Material::Mirror {
            reflectance: t.unit_rgb("reflectance")?,
        },
        MaterialKind::Glass => {
            let at = t.req::<f32>("ior")?;
            let ior = t.cx.finite(at.span(), &t.field("ior"), *at.get_ref())?;
            let (lo, hi) = IOR_RANGE;
            if !(lo..=hi).contains(&ior) {
                return Err(t.cx.err(
                    at.span(),
                    &t.field("ior"),
                    format!("{ior} is outside the allowed range [{lo}, {hi}]"),
                ));
            }
            Material::Glass { ior }
        }
    })
}

/// What the shapes add to as they are read: meshes bring materials (their
/// MTL files') and lights (their emissive triangles).
struct Model {
    materials: Vec<Material>,
    names: BTreeMap<String, usize>,
    shapes: Vec<Shape>,
    lights: Vec<Light>,
}

/// One `[[shape]]`: one primitive, or several for polygons and meshes.
fn read_shape(t: &Table, model: &mut Model) -> Result<(), SceneError> {
    let kind = t.kind(SHAPE_KINDS)?;
    if let ShapeKind::Mesh = kind {
        return mesh::read_mesh(t, model);
    }
    let names = &model.names;
    let one = |geometry: Geometry, material: usize| Ok(vec![Shape::new(geometry, material)]);
    let shapes: Vec<Shape> = match kind {
        ShapeKind::Sphere => {
            let center = t.point("center")?;
            let radius = t.positive("radius", None)?;
            one(Geometry::Sphere { center, radius }, t.material(names)?)
        }
        ShapeKind::Cylinder => {
            let base = t.point("base")?;
            let axis_at = t.req::<[f32; 3]>("axis")?;
            let axis = t.check_vec3("axis", &axis_at)?;
            if axis.length() == 0.0 {
                return Err(t.cx.err(
                    axis_at.span(),
                    &t.field("axis"),
                    "must not be the zero vector".into(),
                ));
            }
            let radius = t.positive("radius", None)?;
            let height = t.positive("height", None)?;
            let axis = axis.normalize();
            let geometry = Geometry::Cylinder {
                base,
                axis,
                radius,
                height,
            };
            one(geometry, t.material(names)?)
        }
        ShapeKind::Parallelogram => {
            let (corner, edge1, edge2) = t.parallelogram()?;
            let geometry = Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            };
            one(geometry, t.material(names)?)
        }
        ShapeKind::Triangle => {
            let at = t.req::<[[Coord; 3]; 3]>("vertices")?;
            let field = t.field("vertices");
            let mut v = [Vec3::ZERO; 3];
            for (p, &asked) in v.iter_mut().zip(at.get_ref()) {
                *p = t.cx.local(t.cx.point(at.span(), &field, asked)?);
            }
            t.cx.nondegenerate(at.span(), &field, v[1] - v[0], v[2] - v[0])?;
            let [v0, v1, v2] = v;
            one(Geometry::Triangle { v0, v1, v2 }, t.material(names)?)
        }
        ShapeKind::Polygon => {
            let material = t.material(names)?;
            let at = t.req::<Vec<[Coord; 3]>>("vertices")?;
            let field = t.field("vertices");
            let v: Vec<Vec3> = at
                .get_ref()
                .iter()
                .map(|p| Ok(t.cx.local(t.cx.point(at.span(), &field, *p)?)))
                .collect::<Result<_, _>>()?;
            let triangles =
                triangulate_convex_polygon(&v).map_err(|msg| t.cx.err(at.span(), &field, msg))?;
            Ok(triangles
                .into_iter()
                .map(|geometry| Shape::new(geometry, material))
                .collect())
        }
        ShapeKind::Mesh => Ok(Vec::new()),
    }?;
    model.shapes.extend(shapes);
    Ok(())
}

/// One `[[light]]`. Area lights are also shapes (the camera sees them), of an
/// emitter material of their own.
fn read_light(
    t: &Table,
    materials: &mut Vec<Material>,
    shapes: &mut Vec<Shape>,
) -> Result<Light, SceneError> {
    match t.kind(LIGHT_KINDS)? {
        LightKind::Point => Ok(Light::Point {
            position: t.point("position")?,
            intensity: t.nonnegative_rgb("intensity")?,
        }),
        LightKind::Area => {
            let (corner, edge1, edge2) = t.parallelogram()?;
            let geometric = edge1.cross(edge2).normalize();
            let normal = match t.get::<[f32; 3]>("normal")? {
                None => geometric,
                Some(at) => {
                    let field = t.field("normal");
                    let n = t.check_vec3("normal", &at)?;
                    if n.length() == 0.0 {
                        return Err(t.cx.err(
                            at.span(),
                            &field,
                            "must not be the zero vector".into(),
                        ));
                    }
                    let n = n.normalize();
                    if n.dot(geometric).abs() < 1.0 - 1e-5 {
                        return Err(t.cx.err(at.span(), &field, format!("{:?} is not perpendicular to the light's plane (edge1 x edge2 gives {:?})", n.to_array(), geometric.to_array())));
                    }
                    n
                }
            };
            let radiance = t.nonnegative_rgb("radiance")?;
            let geometry = Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            };
            shapes.push(Shape::new(geometry, materials.len()));
            materials.push(Material::Emitter {
                radiance,
                normal: Some(normal),
            });
            Ok(Light::Area {
                corner,
                edge1,
                edge2,
                normal,
                radiance,
            })
        }
    }
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

// ---- reading one table ---------------------------------------------------------------

/// One table of the document being read: every error about its fields is
/// placed at the span of the key, value or table it is about.
struct Table<'c, 'a> {
    cx: &'c Cx<'a>,
    /// Dotted path of the table (`camera`, `materials.gold`, `shape[6]`);
    /// empty at the top level.
    path: String,
    /// The header (`[camera]`, `[[shape]]`) or the whole inline table; 0..0
    /// for a table that is not in the document (its fields take defaults).
    span: Span,
    map: &'c DeTable<'a>,
}

impl<'c, 'a> Table<'c, 'a> {
    /// The table `value`, at `path`, written as `key`.
    fn new(
        cx: &'c Cx<'a>,
        path: String,
        key: &str,
        value: &'c Value<'a>,
    ) -> Result<Self, SceneError> {
        match value.get_ref() {
            DeValue::Table(map) => Ok(Table {
                cx,
                path,
                span: value.span(),
                map,
            }),
            other => Err(cx.err(
                value.span(),
                key,
                format!(
                    "invalid type: {}, expected a table{}",
                    other.type_str(),
                    at_path(&path, "")
                ),
            )),
        }
    }

    /// The dotted path of a field of this table.
    fn field(&self, key: &str) -> String {
        if self.path.is_empty() {
            key.to_string()
        } else {
            format!("{}.{key}", self.path)
        }
    }

    /// The sub-table `key`; when it is absent, `absent` (empty: its fields
    /// take their defaults) or, with None, a missing-field error.
    fn table(&self, key: &str, absent: Option<&'c DeTable<'a>>) -> Result<Self, SceneError> {
        match (self.map.get(key), absent) {
            (Some(value), _) => Table::new(self.cx, self.field(key), key, value),
            (None, Some(map)) => Ok(Table {
                cx: self.cx,
                path: self.field(key),
                span: 0..0,
                map,
            }),
            (None, None) => Err(self.missing(key)),
        }
    }

    /// The tables of the array `key` (`[[shape]]`, or an inline array of
    /// inline tables), at paths `key[0]`, `key[1]`...; none when absent.
    fn array(&self, key: &str) -> Result<Vec<Self>, SceneError> {
        let Some(value) = self.map.get(key) else {
            return Ok(Vec::new());
        };
        let DeValue::Array(items) = value.get_ref() else {
            return Err(self.cx.err(
                value.span(),
                key,
                format!(
                    "invalid type: {}, expected an array of tables ([[{key}]])",
                    value.get_ref().type_str()
                ),
            ));
        };
        items
            .iter()
            .enumerate()
            .map(|(i, item)| {
                let path = format!("{}[{i}]", self.field(key));
                Table::new(self.cx, path.clone(), &path, item)
            })
            .collect()
    }

    /// Refuses any key but `allowed` (and `type` in a tagged table), at the
    /// first unknown key in the text.
    fn only(&self, allowed: &[&str], tagged: bool) -> Result<(), SceneError> {
        let unknown = self
            .map
            .keys()
            .filter(|k| {
                !(allowed.contains(&k.get_ref().as_ref()) || tagged && *k.get_ref() == "type")
            })
            .min_by_key(|k| k.span().start);
        match unknown {
            None => Ok(()),
            Some(key) => Err(self.cx.err(
                key.span(),
                key.get_ref(),
                format!(
                    "unknown field `{}`{}, expected {}",
                    key.get_ref(),
                    within(&self.path),
                    one_of(allowed)
                ),
            )),
        }
    }

    /// A tagged table's `type` among `kinds`; the table may hold that kind's
    /// fields only.
    fn kind<K: Copy>(&self, kinds: &Kinds<K>) -> Result<K, SceneError> {
        let asked = self.req::<String>("type")?;
        let Some(&(_, kind, fields)) = kinds.iter().find(|k| k.0 == asked.get_ref()) else {
            let names: Vec<&str> = kinds.iter().map(|k| k.0).collect();
            return Err(self.cx.err(
                asked.span(),
                "type",
                format!(
                    "unknown variant `{}`{}, expected {}",
                    asked.get_ref(),
                    within(&self.field("type")),
                    one_of(&names)
                ),
            ));
        };
        self.only(fields, true)?;
        Ok(kind)
    }

    /// The field `key` as a `T`, with its value's span; None when absent.
    fn get<T: DeserializeOwned>(&self, key: &str) -> Result<Option<Spanned<T>>, SceneError> {
        let Some(value) = self.map.get(key) else {
            return Ok(None);
        };
        let span = value.span();
        match T::deserialize(Strict(value.clone())) {
            Ok(v) => Ok(Some(Spanned::new(span, v))),
            Err(e) => {
                // An element's own span when the error is about one.
                let at = e
                    .span
                    .filter(|s| s.start >= span.start && s.end <= span.end)
                    .unwrap_or(span);
                Err(self.cx.err(
                    at,
                    key,
                    format!("{}{}", e.message.trim(), at_path(&self.path, key)),
                ))
            }
        }
    }

    /// The field `key`, which must be present.
    fn req<T: DeserializeOwned>(&self, key: &str) -> Result<Spanned<T>, SceneError> {
        self.get(key)?.ok_or_else(|| self.missing(key))
    }

    /// The field `key`, or `default` placed at the table when absent.
    fn or<T: DeserializeOwned>(&self, key: &str, default: T) -> Result<Spanned<T>, SceneError> {
        Ok(self
            .get(key)?
            .unwrap_or_else(|| Spanned::new(self.span.clone(), default)))
    }

    fn missing(&self, key: &str) -> SceneError {
        self.cx.err(
            self.span.clone(),
            key,
            format!("missing field `{key}`{}", within(&self.path)),
        )
    }

    /// An integer field in lo..=hi (`default` when absent; None: required).
    fn int(&self, key: &str, default: Option<u32>, lo: i64, hi: i64) -> Result<u32, SceneError> {
        let at = match default {
            Some(d) => self.or(key, i64::from(d))?,
            None => self.req::<i64>(key)?,
        };
        let v = self
            .cx
            .int_range(at.span(), &self.field(key), *at.get_ref(), lo, hi)?;
        Ok(v as u32)
    }

    /// A finite number > 0 (`default` when absent; None: required).
    fn positive(&self, key: &str, default: Option<f32>) -> Result<f32, SceneError> {
        let at = match default {
            Some(d) => self.or(key, d)?,
            None => self.req::<f32>(key)?,
        };
        self.cx.positive(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required point or vector.
    fn vec3(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[f32; 3]>(key)?;
        self.check_vec3(key, &at)
    }

    fn check_vec3(&self, key: &str, at: &Spanned<[f32; 3]>) -> Result<Vec3, SceneError> {
        self.cx.vec3(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required point: read in f64, moved and checked (`Cx::point`), and
    /// stored rebased, in f32.
    fn point(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[Coord; 3]>(key)?;
        Ok(self.cx.local(self.check_point(key, &at)?))
    }

    /// A point in the world's frame, in f64 (not yet rebased).
    fn check_point(&self, key: &str, at: &Spanned<[Coord; 3]>) -> Result<DVec3, SceneError> {
        self.cx.point(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required colour with each channel in [0, 1].
    fn unit_rgb(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[f32; 3]>(key)?;
        self.cx.unit_rgb(at.span(), &self.field(key), *at.get_ref())
    }

    /// A required colour with each channel >= 0.
    fn nonnegative_rgb(&self, key: &str) -> Result<Vec3, SceneError> {
        let at = self.req::<[f32; 3]>(key)?;
        self.cx
            .nonnegative_rgb(at.span(), &self.field(key), *at.get_ref())
    }

    /// `corner`, `edge1` and `edge2` of a parallelogram of nonzero area.
    fn parallelogram(&self) -> Result<(Vec3, Vec3, Vec3), SceneError> {
        let corner = self.point("corner")?;
        let edge1 = self.vec3("edge1")?;
        let edge2_at = self.req::<[f32; 3]>("edge2")?;
        let edge2 = self.check_vec3("edge2", &edge2_at)?;
        self.cx
            .nondegenerate(edge2_at.span(), &self.field("edge2"), edge1, edge2)?;
        Ok((corner, edge1, edge2))
    }

    /// The index of the material the table names.
    fn material(&self, names: &BTreeMap<String, usize>) -> Result<usize, SceneError> {
        let at = self.req::<String>("material")?;
        self.material_named(names, &at, "material")
    }

    /// The index of the material named by the value `at` of field `key`.
    fn material_named(
        &self,
        names: &BTreeMap<String, usize>,
        at: &Spanned<String>,
        key: &str,
    ) -> Result<usize, SceneError> {
        names.get(at.get_ref()).copied().ok_or_else(|| {
            let known: Vec<_> = names.keys().cloned().collect();
            self.cx.err(
                at.span(),
                &self.field(key),
                format!(
                    "no material named {:?} (defined: {})",
                    at.get_ref(),
                    if known.is_empty() {
                        "none".to_string()
                    } else {
                        known.join(", ")
                    }
                ),
            )
        })
    }
}

/// One value read through serde. Unlike toml's own deserializer it refuses
/// arrays longer than what they are read into (`[1.0, 2.0, 3.0, 4.0]` as a
/// `[f32; 3]`), and every error keeps the span of the value (the array or
/// element) it is about.
struct Strict<'a>(Value<'a>);

#[derive(Debug)]
struct StrictError {
    message: String,
    span: Option<Span>,
}

impl std::fmt::Display for StrictError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for StrictError {}

impl serde::de::Error for StrictError {
    fn custom<T: std::fmt::Display>(message: T) -> Self {
        StrictError {
            message: message.to_string(),
            span: None,
        }
    }
}

impl<'de> serde::Deserializer<'de> for Strict<'de> {
    type Error = StrictError;

    fn deserialize_any<V: serde::de::Visitor<'de>>(
        self,
        visitor: V,
    ) -> Result<V::Value, StrictError> {
        let span = self.0.span();
        let placed = |mut e: StrictError| {
            e.span.get_or_insert_with(|| span.clone());
            e
        };
        match self.0.into_inner() {
            DeValue::Array(items) => {
                let mut seq = SeqDeserializer::new(items.into_iter().map(Strict));
                let v = visitor.visit_seq(&mut seq).map_err(placed)?;
                seq.end().map_err(placed)?;
                Ok(v)
            }
            other => ValueDeserializer::from(Spanned::new(span.clone(), other))
                .deserialize_any(visitor)
                .map_err(|e| StrictError {
                    message: e.message().to_string(),
                    span: e.span().or(Some(span.clone())),
                }),
        }
    }

    serde::forward_to_deserialize_any! {
        bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
        bytes byte_buf option unit unit_struct newtype_struct seq tuple
        tuple_struct map struct enum identifier ignored_any
    }
}

impl<'de> IntoDeserializer<'de, StrictError> for Strict<'de> {
    type Deserializer = Self;

    fn into_deserializer(self) -> Self {
        self
    }
}

/// " in PATH", or nothing at the top level.
fn within(path: &str) -> String {
    if path.is_empty() {
        String::new()
    } else {
        format!(" in {path}")
    }
}

/// ", at PATH.KEY" for a field of a table (", at PATH" for the table
/// itself), or nothing at the top level.
fn at_path(path: &str, key: &str) -> String {
    match (path, key) {
        ("", _) => String::new(),
        (_, "") => format!(", at {path}"),
        _ => format!(", at {path}.{key}"),
    }
}

/// "`a`" or "one of `a`, `b`".
fn one_of(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.len() {
        1 => quoted[0].clone(),
        _ => format!("one of {}", quoted.join(", ")),
    }
}

// ---- where things are, and overrides -----------------------------------------------

/// The sources of the document: the file, then each override's value, at
/// offsets past the file's end (their spans are moved there), so that one
/// span says which source and line a value came from.
struct Cx<'a> {
    file: PathBuf,
    text: &'a str,
    base_dir: PathBuf,
    overrides: Vec<Override<'a>>,
    /// Added to every point as it is read (`load_scene_str_translated`).
    translate: DVec3,
    /// The scene's local origin in the world's frame: points are stored
    /// relative to it.
    origin: DVec3,
}

struct Override<'a> {
    /// The key path as given, e.g. `shape[1].radius`.
    key: &'a str,
    /// The value's TOML text.
    value: &'a str,
    /// Where the value's text starts in the document's offsets.
    start: usize,
}

impl Override<'_> {
    /// What errors about this override show as their file.
    fn source(&self) -> PathBuf {
        PathBuf::from(format!("--set {}", self.key))
    }
}

impl<'a> Cx<'a> {
    fn new(text: &'a str, path: &Path, overrides: &'a [(String, String)]) -> Self {
        let mut start = text.len() + 1;
        let overrides = overrides
            .iter()
            .map(|(key, value)| {
                let value = value.trim();
                let o = Override {
                    key: key.trim(),
                    value,
                    start,
                };
                start += value.len() + 1;
                o
            })
            .collect();
        Cx {
            file: path.to_path_buf(),
            text,
            base_dir: path.parent().unwrap_or(Path::new(".")).to_path_buf(),
            overrides,
            translate: DVec3::ZERO,
            origin: DVec3::ZERO,
        }
    }

    /// An error about what `span` covers.
    fn err(&self, span: Span, field: &str, message: String) -> SceneError {
        let (file, line) = match self.overrides.iter().rev().find(|o| span.start >= o.start) {
            Some(o) => (o.source(), line_of(o.value, span.start - o.start)),
            None => (self.file.clone(), line_of(self.text, span.start)),
        };
        SceneError {
            file,
            line,
            field: field.to_string(),
            message,
        }
    }

    /// A TOML syntax error: its line, and the key written on that line.
    fn syntax_error(&self, e: &toml::de::Error) -> SceneError {
        let start = e.span().map_or(0, |s| s.start);
        SceneError {
            file: self.file.clone(),
            line: line_of(self.text, start),
            field: key_before(self.text, start).unwrap_or_else(|| "(syntax)".into()),
            message: e.message().trim().to_string(),
        }
    }

    /// Splices an override into the document, its spans moved to its offsets.
    fn apply_override(&self, root: &mut DeTable<'a>, o: &Override<'a>) -> Result<(), SceneError> {
        let fail = |line: usize, message: String| SceneError {
            file: o.source(),
            line,
            field: o.key.to_string(),
            message,
        };
        let value = DeValue::parse(o.value).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            let message = format!("{:?} is not a TOML value: {}", o.value, e.message().trim());
            fail(line_of(o.value, at), message)
        })?;
        let path = key_path(o.key).map_err(|m| fail(1, m))?;
        let span = o.start..o.start + o.value.len();
        set_at(root, &path, moved(value, o.start), &span).map_err(|m| fail(1, m))
    }
}

/// 1-based line of a byte offset.
pub(super) fn line_of(text: &str, offset: usize) -> usize {
    let end = offset.min(text.len());
    text.as_bytes()[..end]
        .iter()
        .filter(|&&b| b == b'\n')
        .count()
        + 1
}

/// What ends the text before a key on its line: a comma, or the brace that
/// opens an inline table. (A constant, so that no brace sits unbalanced
/// inside a function's body for tools that count braces.)
const BEFORE_KEY: [char; 2] = [',', '\u{7b}'];

/// For a syntax error at a value, the key on the same line (`vfov = = 1` -> vfov).
fn key_before(text: &str, offset: usize) -> Option<String> {
    let end = offset.min(text.len());
    let start = text.as_bytes()[..end]
        .iter()
        .rposition(|&b| b == b'\n')
        .map_or(0, |i| i + 1);
    let line = text.get(start..end)?;
    let key = line.rsplit_once('=')?.0.rsplit(BEFORE_KEY).next()?.trim();
    (!key.is_empty()).then(|| key.to_string())
}

/// One step of an override's key path: a key, and an index into the array
/// of tables it names.
type Step = (String, Option<usize>);

/// `shape[1].radius` -> [("shape", Some(1)), ("radius", None)].
fn key_path(path: &str) -> Result<Vec<Step>, String> {
    let bad = || {
        format!("{path:?} is not a key path (keys joined by dots, each with an optional [index], e.g. shape[1].radius)")
    };
    let key_char = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
    path.split('.')
        .map(|step| {
            let (key, index) = match step.split_once('[') {
                None => (step, None),
                Some((key, rest)) => {
                    let digits = rest.strip_suffix(']').ok_or_else(bad)?;
                    (key, Some(digits.parse::<usize>().map_err(|_| bad())?))
                }
            };
            if key.is_empty() || !key.chars().all(key_char) {
                return Err(bad());
            }
            Ok((key.to_string(), index))
        })
        .collect()
}

/// Sets `value` at `path` in `table`, creating missing tables on the way;
/// an index one past an array's end appends.
fn set_at<'a>(
    table: &mut DeTable<'a>,
    path: &[Step],
    value: Value<'a>,
    span: &Span,
) -> Result<(), String> {
    let Some(((key, index), rest)) = path.split_first() else {
        return Err("an empty key path".into());
    };
    let new_key = || Spanned::new(span.clone(), DeString::Owned(key.clone()));
    let slot = match index {
        None if rest.is_empty() => {
            table.remove(key.as_str());
            table.insert(new_key(), value);
            return Ok(());
        }
        None => table
            .entry(new_key())
            .or_insert_with(|| Spanned::new(span.clone(), DeValue::Table(DeTable::new()))),
        Some(i) => {
            let items = match table.get_mut(key.as_str()).map(Spanned::get_mut) {
                Some(DeValue::Array(items)) => items,
                Some(other) => {
                    return Err(format!(
                        "`{key}` is not an array (its value is of type {})",
                        other.type_str()
                    ))
                }
                None if *i == 0 && rest.is_empty() => {
                    let items = std::iter::once(value).collect();
                    table.insert(new_key(), Spanned::new(span.clone(), DeValue::Array(items)));
                    return Ok(());
                }
                None => return Err(format!("the scene has no `{key}`")),
            };
            let len = items.len();
            if *i == len && rest.is_empty() {
                items.push(value);
                return Ok(());
            }
            match items.get_mut(*i) {
                Some(item) if rest.is_empty() => {
                    *item = value;
                    return Ok(());
                }
                Some(item) => item,
                None => return Err(format!("`{key}` has {len} entries: there is no {key}[{i}]")),
            }
        }
    };
    match slot.get_mut() {
        DeValue::Table(inner) => set_at(inner, rest, value, span),
        other => Err(format!(
            "`{key}` is not a table (its value is of type {})",
            other.type_str()
        )),
    }
}

/// `value` with every span moved by `by`.
fn moved(value: Value<'_>, by: usize) -> Value<'_> {
    let span = value.span();
    let span = span.start + by..span.end + by;
    let inner = match value.into_inner() {
        DeValue::Array(items) => DeValue::Array(items.into_iter().map(|v| moved(v, by)).collect()),
        DeValue::Table(map) => DeValue::Table(
            map.into_iter()
                .map(|(k, v)| {
                    let ks = k.span();
                    let k = Spanned::new(ks.start + by..ks.end + by, k.into_inner());
                    (k, moved(v, by))
                })
                .collect(),
        ),
        other => other,
    };
    Spanned::new(span, inner)
}

// ---- checks of values -----------------------------------------------------------------

impl Cx<'_> {
    fn finite(&self, s: Span, field: &str, v: f32) -> Result<f32, SceneError> {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(s, field, format!("{v} is not a finite number")))
        }
    }

    fn vec3(&self, s: Span, field: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        for x in v {
            self.finite(s.clone(), field, x)?;
        }
        let v = Vec3::from(v);
        if v.abs().max_element() > MAX_COORDINATE {
            return Err(self.err(
                s,
                field,
                format!(
                    "{:?} is too large: coordinates must stay within {MAX_COORDINATE:e}",
                    v.to_array()
                ),
            ));
        }
        Ok(v)
    }

    /// A point in f64, moved by the loader's translation: finite, and within
    /// MAX_COORDINATE of the world's origin.
    fn point(&self, s: Span, field: &str, v: [Coord; 3]) -> Result<DVec3, SceneError> {
        for x in v {
            if !x.0.is_finite() {
                return Err(self.err(s, field, format!("{} is not a finite number", x.0)));
            }
        }
        let p = dvec3(v) + self.translate;
        if p.abs().max_element() > f64::from(MAX_COORDINATE) {
            return Err(self.err(
                s,
                field,
                format!(
                    "{:?} is too large: coordinates must stay within {MAX_COORDINATE:e}",
                    p.to_array()
                ),
            ));
        }
        Ok(p)
    }

    /// A point of the world's frame in the scene's local frame, in f32.
    fn local(&self, p: DVec3) -> Vec3 {
        (p - self.origin).as_vec3()
    }

    fn positive(&self, s: Span, field: &str, v: f32) -> Result<f32, SceneError> {
        let v = self.finite(s.clone(), field, v)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(s, field, format!("{v} must be greater than 0")))
        }
    }

    fn unit_rgb(&self, s: Span, field: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
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

    fn nonnegative_rgb(&self, s: Span, field: &str, v: [f32; 3]) -> Result<Vec3, SceneError> {
        let c = self.vec3(s.clone(), field, v)?;
        if c.min_element() < 0.0 {
            return Err(self.err(s, field, format!("{v:?}: each channel must be >= 0")));
        }
        Ok(c)
    }

    fn int_range(&self, s: Span, field: &str, v: i64, lo: i64, hi: i64) -> Result<i64, SceneError> {
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

    fn nondegenerate(&self, s: Span, field: &str, a: Vec3, b: Vec3) -> Result<(), SceneError> {
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
