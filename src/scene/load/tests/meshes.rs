//! OBJ meshes with MTL materials: the mapping of MTL materials (the book,
//! "OBJ meshes and MTL materials"), the overrides, emissive triangles as
//! lights, vertex normals, and errors that name the OBJ or MTL file and
//! line as well as the scene's `file` field.

use std::path::Path;

use glam::Vec3;

use super::paper_scene;
use crate::scene::{load_scene, Geometry, Light, Material, Scene, SceneError};

/// A scene whose one shape is `mesh.obj` (with `extra` lines in its
/// [[shape]]), with a point light unless `light` is false.
fn scene_text(extra: &str, light: bool) -> String {
    let light = if light {
        "[[light]]\ntype = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n"
    } else {
        ""
    };
    format!(
        "[camera]\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nvfov = 40.0\nwidth = 8\nheight = 8\n\
         [materials]\ngrey = {{ type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }}\n\
         mirror = {{ type = \"mirror\", reflectance = [0.9, 0.9, 0.9] }}\n\
         [[shape]]\ntype = \"mesh\"\nfile = \"mesh.obj\"\n{extra}\n{light}"
    )
}

/// The line of `file = "mesh.obj"` in `scene_text`.
const FILE_LINE: usize = 12;

/// Writes the files in a fresh folder and loads the scene.
fn load(files: &[(&str, &str)], extra: &str, light: bool) -> Result<Scene, SceneError> {
    load_in(tempfile::tempdir().unwrap().path(), files, extra, light)
}

/// Writes the files in `dir` and loads the scene.
fn load_in(
    dir: &Path,
    files: &[(&str, &str)],
    extra: &str,
    light: bool,
) -> Result<Scene, SceneError> {
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene_text(extra, light)).unwrap();
    load_scene(&path)
}

/// Expects an error at the scene's `file` field whose message starts with
/// `<dir>/<file>:<line>:` and contains `says`.
fn expect_error(files: &[(&str, &str)], extra: &str, file: &str, line: usize, says: &str) {
    let dir = tempfile::tempdir().unwrap();
    let e = load_in(dir.path(), files, extra, true).expect_err("should fail");
    assert_eq!(
        (e.line, e.field.as_str()),
        (FILE_LINE, "shape[0].file"),
        "{e}"
    );
    let kind = if file.ends_with(".mtl") { "MTL" } else { "OBJ" };
    let at = format!("{kind} file {}:{line}: ", dir.path().join(file).display());
    assert!(
        e.message.starts_with(&at),
        "{e}\n(expected it to start with {at})"
    );
    assert!(e.message.contains(says), "{e}");
    assert!(e.file.ends_with("scene.toml"), "{e}");
}

const QUAD: &str = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n";

const MTL: &str = "\
newmtl plain
Kd 0.5 0.25 0.125

newmtl mirror3
illum 3
Kd 0.1 0.1 0.1
Ks 0.9 0.8 0.7

newmtl mirror5
illum 5
Ks 0.5 0.5 0.5

newmtl glass7
illum 7
Ni 1.5

newmtl glass4
illum 4
Kd 0.2 0.2 0.2
Ni 1.33

newmtl glass_ni1
illum 4
Kd 0.3 0.3 0.3
Ni 1.0

newmtl dull_mirror
illum 3
Kd 0.4 0.4 0.4
Ks 0 0 0

newmtl lamp
Kd 0.8 0.8 0.8
Ke 4 3 2
";

/// One quad (two triangles) per material, each its own object.
fn every_material_obj() -> String {
    let names = [
        "plain",
        "mirror3",
        "mirror5",
        "glass7",
        "glass4",
        "glass_ni1",
        "dull_mirror",
        "lamp",
    ];
    let mut obj = String::from("mtllib m.mtl\n");
    for (i, n) in names.iter().enumerate() {
        let y = i as f32;
        obj += &format!(
            "o obj_{n}\nusemtl {n}\nv 0 {y} 0\nv 1 {y} 0\nv 1 {y} 1\nv 0 {y} 1\nf -4 -3 -2 -1\n"
        );
    }
    obj
}

/// The material of the triangles at height y (every quad lies in a plane y = const).
fn material_at(scene: &Scene, y: f32) -> Material {
    let s = scene
        .shapes
        .iter()
        .find(|s| matches!(s.geometry, Geometry::Triangle { v0, .. } if v0.y == y))
        .unwrap();
    scene.materials[s.material]
}

#[test]
fn mtl_materials_map_as_the_readme_says() {
    let obj = every_material_obj();
    let s = load(&[("mesh.obj", &obj), ("m.mtl", MTL)], "", true).unwrap();
    let rgb = Vec3::new;
    let diffuse = |r, g, b| Material::Diffuse {
        albedo: rgb(r, g, b),
    };
    let mirror = |r, g, b| Material::Mirror {
        reflectance: rgb(r, g, b),
    };
    // In the order of `every_material_obj`'s names: the quad at y = i.
    let expected = [
        diffuse(0.5, 0.25, 0.125),
        mirror(0.9, 0.8, 0.7),
        mirror(0.5, 0.5, 0.5),
        Material::Glass { ior: 1.5 },
        Material::Glass { ior: 1.33 },
        // Ni 1 bends nothing: illum 4 is then its Kd.
        diffuse(0.3, 0.3, 0.3),
        // illum 3 with a black Ks is its Kd.
        diffuse(0.4, 0.4, 0.4),
        Material::Emitter {
            radiance: rgb(4.0, 3.0, 2.0),
            normal: None,
        },
    ];
    for (y, material) in expected.into_iter().enumerate() {
        assert_eq!(material_at(&s, y as f32), material, "the quad at y = {y}");
    }
    // The emitter's two triangles are one light (beside the point light),
    // of power pi * area * Ke.
    let lights: Vec<&Light> = s
        .lights
        .iter()
        .filter(|l| matches!(l, Light::Triangles { .. }))
        .collect();
    assert_eq!(lights.len(), 1);
    let Light::Triangles {
        first,
        count,
        radiance,
    } = *lights[0]
    else {
        unreachable!()
    };
    assert_eq!((count, radiance), (2, rgb(4.0, 3.0, 2.0)));
    assert!(s.shapes[first..first + count]
        .iter()
        .all(|t| matches!(s.materials[t.material], Material::Emitter { .. })));
    let power = lights[0].power(&s.shapes);
    assert!(
        (power - std::f32::consts::PI * rgb(4.0, 3.0, 2.0))
            .abs()
            .max_element()
            < 1e-5,
        "{power}"
    );
    // Each MTL material is a scene material named <file>:<name>: another
    // shape can use it by that name.
    let reuse = "[[shape]]\ntype = \"sphere\"\ncenter = [0.0, 9.0, 0.0]\nradius = 0.5\nmaterial = \"mesh.obj:glass4\"";
    let temp = tempfile::tempdir().unwrap();
    let dir = temp.path();
    let s = load_in(dir, &[("mesh.obj", &obj), ("m.mtl", MTL)], "", true).unwrap();
    let before = s.materials.len();
    let text = scene_text("", true) + reuse + "\n";
    std::fs::write(dir.join("scene2.toml"), text).unwrap();
    let s2 = load_scene(&dir.join("scene2.toml")).unwrap();
    let sphere = s2
        .shapes
        .iter()
        .find(|x| matches!(x.geometry, Geometry::Sphere { .. }))
        .unwrap();
    assert_eq!(s2.materials[sphere.material], Material::Glass { ior: 1.33 });
    assert_eq!(
        s2.materials.len(),
        before,
        "the named material is reused, not added"
    );
}

#[test]
fn a_material_on_the_shape_overrides_every_mtl_material() {
    let obj = every_material_obj();
    let files = [("mesh.obj", obj.as_str()), ("m.mtl", MTL)];
    let s = load(&files, "material = \"grey\"", true).unwrap();
    assert_eq!(s.shapes.len(), 16);
    assert!(
        s.shapes.iter().all(|x| x.material == 0),
        "grey is material 0"
    );
    assert_eq!(s.lights.len(), 1, "the lamp's Ke is overridden too");
    // Without the MTL file: the override needs none.
    let s = load(&[("mesh.obj", obj.as_str())], "material = \"grey\"", true).unwrap();
    assert_eq!(s.shapes.len(), 16);
    // Per object: the named objects take theirs, the rest their MTL's.
    let extra = "object_materials = { obj_plain = \"mirror\", obj_lamp = \"grey\" }";
    let s = load(&files, extra, true).unwrap();
    assert_eq!(
        material_at(&s, 0.0),
        Material::Mirror {
            reflectance: Vec3::splat(0.9)
        }
    );
    assert_eq!(
        material_at(&s, 7.0),
        Material::Diffuse {
            albedo: Vec3::splat(0.5)
        }
    );
    assert_eq!(material_at(&s, 3.0), Material::Glass { ior: 1.5 });
    assert_eq!(s.lights.len(), 1, "obj_lamp no longer emits");
    // An object the OBJ does not have, named at its own line.
    let extra = "object_materials = { obj_none = \"grey\" }";
    let e = load(&files, extra, true).unwrap_err();
    assert_eq!(
        (e.line, e.field.as_str()),
        (FILE_LINE + 1, "shape[0].object_materials.obj_none"),
        "{e}"
    );
    assert!(
        e.message.contains("obj_plain"),
        "names the objects it has: {e}"
    );
}

#[test]
fn emissive_triangles_light_a_scene_without_any_light() {
    let obj = "mtllib m.mtl\no lamp\nusemtl lamp\nv 0 2 0\nv 0 2 1\nv 1 2 1\nv 1 2 0\nf 1 2 3 4\n\
               o floor\nusemtl plain\nv -5 0 -5\nv 5 0 -5\nv 5 0 5\nv -5 0 5\nf 5 6 7 8\n";
    let s = load(&[("mesh.obj", obj), ("m.mtl", MTL)], "", false).unwrap();
    assert_eq!(s.lights.len(), 1);
    // Emitters come after the mesh's other triangles, as one run.
    let Light::Triangles { first, count, .. } = s.lights[0] else {
        panic!("{:?}", s.lights)
    };
    assert_eq!((first, count), (2, 2));
    // Overridden, it is no light, and a scene with none is refused.
    let e = load(
        &[("mesh.obj", obj), ("m.mtl", MTL)],
        "material = \"grey\"",
        false,
    )
    .unwrap_err();
    assert_eq!(e.field, "light", "{e}");
}

#[test]
fn vertex_normals_become_shading_normals() {
    // Face 1 has a normal at each corner (one of them unnormalised), face 2
    // at two corners only, face 3 none. Face 1's winding points down (-y)
    // but its normals up: it is turned around.
    let obj = "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nvn 0 2 0\nvn 0.1 1 0\nvn 0 1 0.1\n\
               f 1//1 3//2 2//3\nf 1//1 2//2 3\nf 1 3 4\n";
    let s = load(&[("mesh.obj", obj)], "material = \"grey\"", true).unwrap();
    assert_eq!(s.shapes.len(), 3);
    let Some(n) = s.shapes[0].normals else {
        panic!("face 1 has normals")
    };
    assert!(s.shapes[1].normals.is_none() && s.shapes[2].normals.is_none());
    for v in n {
        assert!((v.length() - 1.0).abs() < 1e-6, "unit: {v}");
    }
    let Geometry::Triangle { v0, v1, v2 } = s.shapes[0].geometry else {
        unreachable!()
    };
    let geometric = (v1 - v0).cross(v2 - v0);
    assert!(
        geometric.y > 0.0,
        "turned to the normals' side: {geometric}"
    );
    // The normals went with their corners.
    assert_eq!(v0, Vec3::ZERO);
    assert_eq!(n[0], Vec3::Y);
    let expect_at = |corner: Vec3, normal: Vec3| {
        let i = [v0, v1, v2].iter().position(|&v| v == corner).unwrap();
        assert!((n[i] - normal.normalize()).length() < 1e-6, "{:?}", n);
    };
    expect_at(Vec3::new(1.0, 0.0, 1.0), Vec3::new(0.1, 1.0, 0.0));
    expect_at(Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.1));
}

#[test]
fn a_face_without_material_names_the_file_and_line() {
    // No MTL at all, and no `material`.
    let no_mtl = format!("{QUAD}g box\nf 1 2 3\n");
    // With an MTL, a face before any usemtl.
    let before_usemtl = format!("mtllib m.mtl\n{QUAD}f 1 2 3\nusemtl plain\nf 1 3 4\n");
    for (files, says) in [
        (vec![("mesh.obj", no_mtl.as_str())], "no material"),
        (
            vec![("mesh.obj", before_usemtl.as_str()), ("m.mtl", MTL)],
            "\"unnamed_object\"",
        ),
    ] {
        expect_error(&files, "", "mesh.obj", 6, says);
    }
}

#[test]
fn a_missing_mtl_names_the_obj_file_and_line() {
    let obj = format!("# a comment\nmtllib nowhere.mtl\n{QUAD}usemtl plain\nf 1 2 3\n");
    expect_error(&[("mesh.obj", &obj)], "", "mesh.obj", 2, "nowhere.mtl");
    // An unknown material name.
    let obj = format!("mtllib m.mtl\n{QUAD}usemtl shiny\nf 1 2 3\n");
    let files = [("mesh.obj", obj.as_str()), ("m.mtl", MTL)];
    expect_error(&files, "", "mesh.obj", 6, "shiny");
}

#[test]
fn bad_face_indices_name_the_file_and_line() {
    let m = "material = \"grey\"";
    for (text, line, says) in [
        (format!("{QUAD}f 1 2 3\nf 1 2 5\n"), 6, "vertex 5"),
        (format!("{QUAD}f 0 1 2\n"), 5, "vertex 0"),
        (format!("{QUAD}f -1 -2 -5\n"), 5, "vertex -5"),
        // A normal index beyond the normals given.
        (format!("{QUAD}vn 0 1 0\nf 1//1 2//2 3//1\n"), 6, "normal 2"),
        (format!("{QUAD}f 1 2\n"), 5, "3 corners"),
    ] {
        expect_error(&[("mesh.obj", &text)], m, "mesh.obj", line, says);
    }
}

#[test]
fn bad_numbers_name_the_file_and_line() {
    let m = "material = \"grey\"";
    for (text, line, says) in [
        (
            "v 0 0 0\nv 1 0 0\nv nan 1 0\nf 1 2 3\n",
            3,
            "NaN is not a finite number",
        ),
        ("v 0 0 0\nv 1 0 inf\nv 0 1 0\nf 1 2 3\n", 2, "inf"),
        ("v 0 0 0\nv 1 0 1e39\nv 0 1 0\nf 1 2 3\n", 2, "finite"),
        (
            "v 0 0 0\nv 1 0x 0\nv 0 1 0\nf 1 2 3\n",
            2,
            "`0x` is not a number",
        ),
        (
            "v 0 0 0\nv 1 0\nv 0 1 0\nf 1 2 3\n",
            2,
            "expected 3 numbers",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 0\nf 1//1 2//1 3//1\n",
            4,
            "not a usable normal",
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 NaN 1\nf 1//1 2//1 3//1\n",
            4,
            "not a usable normal",
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3.5\n", 4, "not an index"),
    ] {
        expect_error(&[("mesh.obj", text)], m, "mesh.obj", line, says);
    }
}

#[test]
fn bad_mtl_statements_name_the_mtl_file_and_line() {
    let obj = format!("mtllib m.mtl\n{QUAD}usemtl a\nf 1 2 3\n");
    for (mtl, line, says) in [
        // tobj itself would panic on a colour of two numbers.
        ("newmtl a\nKd 0.5 0.5\n", 2, "expected 3 numbers"),
        ("newmtl a\n\nKd 0.5 x 0.5\n", 3, "`x` is not a number"),
        ("newmtl a\nKd 0.5 1.5 0.5\n", 2, "[0, 1]"),
        ("newmtl a\nillum 3\nKs 2 0 0\n", 3, "[0, 1]"),
        ("newmtl a\nillum 7\n", 2, "needs Ni"),
        ("newmtl a\nillum 7\nNi 20\n", 3, "outside the allowed range"),
        ("newmtl a\nKe -1 2 0\n", 2, ">= 0"),
        ("newmtl a\nillum x\n", 2, "illum"),
        ("newmtl a\nNs 10\n", 1, "no Kd"),
    ] {
        expect_error(
            &[("mesh.obj", &obj), ("m.mtl", mtl)],
            "",
            "m.mtl",
            line,
            says,
        );
    }
}

#[test]
fn the_measured_cornell_box_loads_from_its_obj() {
    let s = paper_scene("cornell_box_obj");
    // 5 walls, 4 ceiling panels, 10 block faces: 38 triangles, 2 of them the light.
    assert_eq!(s.shapes.len(), 38);
    assert_eq!(s.lights.len(), 1);
    let light = s.lights[0];
    let Light::Triangles { radiance, .. } = light else {
        panic!("{light:?}")
    };
    assert_eq!(radiance, Vec3::new(17.0, 12.0, 4.0));
    // The published opening: 130 x 105 mm.
    assert!((light.area(&s.shapes) - 130.0 * 105.0).abs() < 1e-2);
    // Loaded by name from elsewhere, through the embedded OBJ and MTL.
    let e = crate::scene::embedded::load("cornell_box_obj").unwrap();
    assert_eq!(e.shapes, s.shapes);
    assert_eq!(e.materials, s.materials);
}
