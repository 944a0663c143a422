//! The scene format's sections, one function each: the whole document
//! (`read_scene`), then camera, render, photon_map, materials, shapes and
//! lights, each read through `Table` and checked; mesh shapes in `mesh.rs`.

use std::collections::BTreeMap;

use glam::Vec3;
use toml::de::DeTable;
use toml::Spanned;

use super::super::defaults::{
    default_max_radius, ALPHA_RANGE, CONDUCTOR_INDEX_RANGE, DEFAULT_UP, IOR_RANGE, MAX_BOUNCES,
    MAX_GRID_SIDE, MAX_IMAGE_SIDE, MAX_K, MAX_PHOTONS_STORED, MAX_PROJECTION_RESOLUTION,
    MAX_SHADOW_RAYS, MAX_SPECULAR_DEPTH, MIN_PROJECTION_RESOLUTION, SMOOTH_ALPHA, VFOV_RANGE,
};
use super::super::metals;
use super::super::rebase::Coord;
use super::super::{
    Camera, Geometry, Light, Material, Microfacet, PhotonMapParams, RenderParams, Scene, Shape,
};
use super::context::{Cx, Span};
use super::mesh::{self, Model};
use super::table::{Kinds, Table};
use crate::error::SceneError;

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

#[derive(Clone, Copy)]
enum MaterialKind {
    Diffuse,
    Mirror,
    Glass,
    Conductor,
}

const MATERIAL_KINDS: &Kinds<MaterialKind> = &[
    ("diffuse", MaterialKind::Diffuse, &["albedo"]),
    ("mirror", MaterialKind::Mirror, &["reflectance"]),
    ("glass", MaterialKind::Glass, &["ior"]),
    (
        "conductor",
        MaterialKind::Conductor,
        &[
            "metal",
            "eta",
            "k",
            "tint",
            "alpha",
            "distribution",
            "masking",
        ],
    ),
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

/// The whole document, section by section.
pub(super) fn read_scene(cx: &Cx, root: &DeTable) -> Result<Scene, SceneError> {
    let doc = Table::document(cx, root);
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
            specular_last_only: false,
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
        MaterialKind::Conductor => read_conductor(t)?,
    })
}

/// A metal: `metal` (a name of src/scene/metals.rs) or `eta` and `k`
/// together; `tint` (default white); `alpha` (default 0, smooth).
fn read_conductor(t: &Table) -> Result<Material, SceneError> {
    let index = |key: &str| -> Result<Option<Vec3>, SceneError> {
        let Some(at) = t.get::<[f32; 3]>(key)? else {
            return Ok(None);
        };
        let c = t.cx.vec3(at.span(), &t.field(key), *at.get_ref())?;
        let (lo, hi) = CONDUCTOR_INDEX_RANGE;
        if c.min_element() < lo || c.max_element() > hi || (key == "eta" && c.min_element() <= 0.0)
        {
            let low = if key == "eta" { "(0" } else { "[0" };
            return Err(t.cx.err(
                at.span(),
                &t.field(key),
                format!("{:?}: each channel must be in {low}, {hi}]", at.get_ref()),
            ));
        }
        Ok(Some(c))
    };
    let (eta, k) = match (t.get::<String>("metal")?, index("eta")?, index("k")?) {
        (Some(name), None, None) => metals::metal(name.get_ref()).ok_or_else(|| {
            t.cx.err(
                name.span(),
                &t.field("metal"),
                format!(
                    "unknown metal `{}`, expected one of {}",
                    name.get_ref(),
                    metals::metal_names()
                ),
            )
        })?,
        (None, Some(eta), Some(k)) => (eta, k),
        (Some(name), _, _) => {
            return Err(t.cx.err(
                name.span(),
                &t.field("metal"),
                "give `metal` or `eta` and `k`, not both".into(),
            ))
        }
        _ => {
            return Err(t.cx.err(
                t.span.clone(),
                &t.field("eta"),
                "a conductor needs `metal`, or `eta` and `k` together".into(),
            ))
        }
    };
    let tint = match t.get::<[f32; 3]>("tint")? {
        Some(at) => t.cx.unit_rgb(at.span(), &t.field("tint"), *at.get_ref())?,
        None => Vec3::ONE,
    };
    let at = t.or::<f32>("alpha", 0.0)?;
    let alpha = t.cx.finite(at.span(), &t.field("alpha"), *at.get_ref())?;
    let (lo, hi) = ALPHA_RANGE;
    if !(lo..=hi).contains(&alpha) {
        return Err(t.cx.err(
            at.span(),
            &t.field("alpha"),
            format!("{alpha} is outside the allowed range [{lo}, {hi}]"),
        ));
    }
    let alpha = if alpha < SMOOTH_ALPHA { 0.0 } else { alpha };
    let choice = |key: &str, names: [&str; 2], default: &str| -> Result<bool, SceneError> {
        let at = t.or::<String>(key, default.to_string())?;
        match names.iter().position(|n| n == at.get_ref()) {
            Some(i) => Ok(i == 1),
            None => Err(t.cx.err(
                at.span(),
                &t.field(key),
                format!(
                    "unknown {key} `{}`, expected `{}` or `{}`",
                    at.get_ref(),
                    names[0],
                    names[1]
                ),
            )),
        }
    };
    let mut microfacet = Microfacet {
        beckmann: choice("distribution", ["ggx", "beckmann"], "ggx")?,
        separable: choice(
            "masking",
            ["height-correlated", "separable"],
            "height-correlated",
        )?,
    };
    if alpha == 0.0 {
        microfacet = Microfacet::default(); // a smooth metal has no microfacets
    }
    Ok(Material::Conductor {
        eta,
        k,
        tint,
        alpha,
        microfacet,
    })
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
