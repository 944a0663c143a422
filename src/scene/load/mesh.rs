//! `[[shape]] type = "mesh"`: an OBJ file's triangles (`scene::obj`),
//! placed (p * scale + translate, in f64, then rebased like every other
//! point), with their materials and lights:
//!
//! - a triangle's material is its group's or object's entry in
//!   `object_materials`, else the shape's `material`, else its face's MTL
//!   material, which becomes a scene material named `<file>:<MTL name>`
//!   (`obj::renderer_material` maps it); a face with none of them is an
//!   error naming the OBJ file and the face's line;
//! - triangles whose material emits (an MTL `Ke`) are appended after the
//!   mesh's others, one run per (group or object, material), and each run
//!   is one `Light::Triangles`, sampled by area;
//! - vertex normals ride along as each triangle's shading normals (emitters
//!   need none).

use std::collections::BTreeMap;
use std::ops::Range;

use glam::Vec3;

use super::super::defaults::{DEFAULT_MESH_SCALE, DEFAULT_MESH_TRANSLATE};
use super::super::obj::{self, ObjMesh, ObjTriangle};
use super::super::rebase::Coord;
use super::table::Table;
use crate::error::SceneError;
use crate::scene::{Geometry, Light, Material, Shape};

/// What the shapes add to as they are read: meshes bring materials (their
/// MTL files') and lights (their emissive triangles).
pub(super) struct Model {
    pub(super) materials: Vec<Material>,
    pub(super) names: BTreeMap<String, usize>,
    pub(super) shapes: Vec<Shape>,
    pub(super) lights: Vec<Light>,
}

/// Reads the mesh shape `t` into `model`.
pub(super) fn read_mesh(t: &Table, model: &mut Model) -> Result<(), SceneError> {
    let file = t.req::<String>("file")?;
    let whole = match t.get::<String>("material")? {
        Some(at) => Some(t.material_named(&model.names, &at, "material")?),
        None => None,
    };
    let scale = f64::from(t.positive("scale", Some(DEFAULT_MESH_SCALE))?);
    let translate_at = t.or("translate", DEFAULT_MESH_TRANSLATE.map(|c| Coord(c.into())))?;
    let translate = t.check_point("translate", &translate_at)?;
    let by_object = read_object_materials(t, &model.names)?;
    let path = t.cx.base_dir.join(file.get_ref());
    let at_file = |message: String| t.cx.err(file.span(), &t.field("file"), message);
    let mesh = obj::load(&path, whole.is_none()).map_err(at_file)?;
    for (name, span, _) in &by_object {
        if !mesh.objects.contains(name) {
            return Err(t.cx.err(
                span.clone(),
                &t.field(&format!("object_materials.{name}")),
                format!(
                    "OBJ file {} has no group or object named {name:?} (it has: {})",
                    path.display(),
                    mesh.objects.join(", ")
                ),
            ));
        }
    }
    let mut mtl_to_scene = BTreeMap::new();
    let mut emissive: Vec<((usize, usize), Vec<Shape>)> = Vec::new();
    for tri in &mesh.triangles {
        let object = &mesh.objects[tri.object];
        let chosen = by_object
            .iter()
            .find(|(name, _, _)| name == object)
            .map(|(_, _, m)| *m)
            .or(whole);
        let material = match (chosen, tri.material) {
            (Some(m), _) => m,
            (None, Some(k)) => match mtl_to_scene.get(&k) {
                Some(&m) => m,
                None => {
                    let m = register_mtl(model, &mesh, k, file.get_ref()).map_err(at_file)?;
                    mtl_to_scene.insert(k, m);
                    m
                }
            },
            (None, None) => return Err(at_file(no_material(&path, tri, object))),
        };
        let place = |p: Vec3| t.cx.local(p.as_dvec3() * scale + translate);
        let [v0, v1, v2] = tri.corners.map(place);
        let geometry = Geometry::Triangle { v0, v1, v2 };
        if let Material::Emitter { .. } = model.materials[material] {
            let key = (tri.object, material);
            let shape = Shape::new(geometry, material);
            match emissive.iter_mut().find(|(k, _)| *k == key) {
                Some((_, run)) => run.push(shape),
                None => emissive.push((key, vec![shape])),
            }
        } else {
            model.shapes.push(Shape {
                geometry,
                material,
                normals: tri.normals,
            });
        }
    }
    for ((_, material), run) in emissive {
        let Material::Emitter { radiance, .. } = model.materials[material] else {
            continue;
        };
        let (first, count) = (model.shapes.len(), run.len());
        model.shapes.extend(run);
        let light = Light::Triangles {
            first,
            count,
            radiance,
        };
        // Triangles of no area emit nothing: they are no light.
        if light.area(&model.shapes) > 0.0 {
            model.lights.push(light);
        }
    }
    Ok(())
}

/// `object_materials = { <group or object> = "<material>", ... }`: each
/// name, the span of its value, and the material's index.
fn read_object_materials(
    t: &Table,
    names: &BTreeMap<String, usize>,
) -> Result<Vec<(String, Range<usize>, usize)>, SceneError> {
    let empty = toml::de::DeTable::new();
    let table = t.table("object_materials", Some(&empty))?;
    let mut out = Vec::new();
    for key in table.map.keys() {
        let name = key.get_ref().to_string();
        let at = table.req::<String>(&name)?;
        let material = table.material_named(names, &at, &name)?;
        out.push((name, at.span(), material));
    }
    Ok(out)
}

/// The scene material of MTL material `k` of `mesh`, named
/// `<file>:<MTL name>`: added, or the one of that name already read (an
/// OBJ used twice) when it is the same.
fn register_mtl(model: &mut Model, mesh: &ObjMesh, k: usize, file: &str) -> Result<usize, String> {
    let mtl = &mesh.materials[k];
    let material = obj::renderer_material(mtl)?;
    let name = format!("{file}:{}", mtl.name);
    match model.names.get(&name) {
        Some(&m) if model.materials[m] == material => Ok(m),
        Some(_) => Err(format!(
            "MTL file {}: material {:?} maps to {material:?}, but a different material named {name:?} exists already",
            mtl.file.display(),
            mtl.name
        )),
        None => {
            model.names.insert(name, model.materials.len());
            model.materials.push(material);
            Ok(model.materials.len() - 1)
        }
    }
}

fn no_material(path: &std::path::Path, tri: &ObjTriangle, object: &str) -> String {
    format!(
        "OBJ file {}:{}: this face (of {object:?}) has no material: no `usemtl` of an MTL file before it, and the [[shape]] gives no `material` (nor `object_materials` for {object:?})",
        path.display(),
        tri.line
    )
}
