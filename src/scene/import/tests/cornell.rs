//! The Cornell box of scenes/cornell_box_obj, written in pbrt-v4 and
//! Mitsuba 3 (scenes/tests/import/), loads to the OBJ scene's surfaces,
//! materials, light and camera; its PLY block reads the same in every
//! encoding. (tests/gpu/import.rs renders them against each other.)

use super::*;
use crate::scene::Material;

fn obj_scene() -> Scene {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell_box_obj.toml");
    crate::scene::load_scene(&path).unwrap()
}

/// Every surface that is not an emitter: its geometry's key and albedo, sorted.
fn surfaces(s: &Scene) -> Vec<(Vec<[f64; 3]>, [f32; 3])> {
    let mut v: Vec<_> = s
        .shapes
        .iter()
        .filter_map(|x| match s.materials[x.material] {
            Material::Diffuse { albedo } => Some((key(s, &x.geometry).0, albedo.to_array())),
            Material::Emitter { .. } => None,
            ref m => panic!("{m:?}"),
        })
        .collect();
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    v
}

/// `imported` is the OBJ Cornell box: the same surfaces and albedos, the
/// same light's power and side, the same camera.
pub(super) fn assert_cornell(imported: &Scene) {
    let obj = obj_scene();
    let (a, b) = (surfaces(imported), surfaces(&obj));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!(
            x.0.iter().zip(&y.0).all(|(p, q)| close(*p, *q, 1e-3)),
            "{x:?} {y:?}"
        );
        assert_eq!(x.1, y.1);
    }
    let (pa, pb) = (light_power(imported), light_power(&obj));
    assert_eq!(pa.len(), 1);
    assert!(close(pa[0], pb[0], 1e-3 * pb[0][0]), "{pa:?} {pb:?}");
    assert_eq!(light_normals(imported)[0], Some([0.0, -1.0, 0.0]));
    assert_eq!(light_normals(&obj)[0], Some([0.0, -1.0, 0.0]));
    let (ca, cb) = (&imported.camera, &obj.camera);
    let dir = |c: &crate::scene::Camera| (c.look_at - c.position).normalize();
    assert!(close(
        world(imported, ca.position),
        world(&obj, cb.position),
        1e-3
    ));
    assert!((dir(ca) - dir(cb)).length() < 1e-6 && (ca.up - cb.up).length() < 1e-6);
    assert_eq!(
        (ca.vfov_degrees, ca.width, ca.height),
        (cb.vfov_degrees, cb.width, cb.height)
    );
}

#[test]
fn pbrt_cornell_box_is_the_obj_one() {
    assert_cornell(&load("cornell_box.pbrt"));
}

#[test]
fn pbrt_cornell_box_keeps_its_materials_names_and_hints() {
    let text = fixture_text("cornell_box.pbrt");
    let c = convert_default("cornell_box.pbrt", &text).unwrap();
    for line in [
        "white = { type = \"diffuse\", albedo = [0.725, 0.71, 0.68] }",
        "render with --spp 4.",
        "--method sppm --iterations 4 --photons-per-iteration 100000.",
        "max_specular_depth = 8",
    ] {
        assert!(c.toml.contains(line), "{line}\n{}", c.toml);
    }
    assert!(c.notes.is_empty(), "{:?}", c.notes);
}

#[test]
fn the_ply_block_reads_the_same_in_every_encoding() {
    let text = fixture_text("cornell_box.pbrt");
    let ascii = convert_default("cornell_box.pbrt", &text).unwrap();
    for enc in ["le", "be"] {
        let other = text.replace("tall_block_ascii.ply", &format!("tall_block_{enc}.ply"));
        assert_ne!(other, text);
        let c = convert_default("cornell_box.pbrt", &other).unwrap();
        assert_eq!(c, ascii, "{enc}");
    }
    // and the three files really are the three encodings
    for (file, enc) in [
        ("tall_block_ascii.ply", "ascii"),
        ("tall_block_le.ply", "binary_little_endian"),
        ("tall_block_be.ply", "binary_big_endian"),
    ] {
        let bytes = std::fs::read(dir().join(file)).unwrap();
        assert!(
            bytes.starts_with(format!("ply\nformat {enc} 1.0").as_bytes()),
            "{file}"
        );
    }
}

#[test]
fn mitsuba_cornell_box_is_the_obj_one() {
    assert_cornell(&load("cornell_box.xml"));
}

#[test]
fn mitsuba_defines_set_defaults_and_dollar_parameters() {
    let text = fixture_text("cornell_box.xml");
    let opts = ImportOptions {
        defines: vec![("res".into(), "64".into())],
        ..ImportOptions::default()
    };
    let c = convert_text("cornell_box.xml", &text, &opts).unwrap();
    let s = load_scene_str(&c.toml, Path::new("t")).unwrap();
    assert_eq!((s.camera.width, s.camera.height), (64, 64));
    assert!(c.toml.contains("render with --spp 4."), "{}", c.toml);
    // Mitsuba 0.6's camelCase names read as Mitsuba 3's
    let old = text
        .replace("fov_axis", "fovAxis")
        .replace("to_world", "toWorld")
        .replace("sample_count", "sampleCount");
    let (_, s) = convert_and_load("cornell_box.xml", &old);
    assert_cornell(&s);
}

#[test]
fn mitsuba_max_depth_counts_the_camera_segment() {
    // Mitsuba's max_depth D is D - 1 bounces (2: direct light); pbrt's
    // maxdepth 8 above gives 8.
    let text = fixture_text("cornell_box.xml");
    let depth = |d: &str, opts: &ImportOptions| {
        let t = replace_once(&text, "name=\"max_depth\" value=\"8\"", d);
        convert_text("cornell_box.xml", &t, opts)
    };
    let lenient = ImportOptions {
        lenient: true,
        ..ImportOptions::default()
    };
    for (d, bounces) in [("8", 7), ("2", 1), ("65", 64), ("1000", 64), ("-1", 10)] {
        let c = depth(
            &format!("name=\"max_depth\" value=\"{d}\""),
            &ImportOptions::default(),
        )
        .unwrap_or_else(|e| panic!("{d}: {e}"));
        for line in [
            format!("max_specular_depth = {bounces}\n"),
            format!("max_bounces = {bounces}\n"),
        ] {
            assert!(c.toml.contains(&line), "{d}: {line}\n{}", c.toml);
        }
        assert!(c.notes.is_empty(), "{d}: {:?}", c.notes);
    }
    // 1 renders emitters alone, which photonmap cannot
    let one = "name=\"max_depth\" value=\"1\"";
    let e = depth(one, &ImportOptions::default()).unwrap_err();
    assert!(e.to_string().contains("--lenient: max_depth 2"), "{e}");
    let c = depth(one, &lenient).unwrap();
    assert!(c.toml.contains("max_specular_depth = 1\n"), "{}", c.toml);
    assert_eq!(c.notes.len(), 1, "{:?}", c.notes);
}

/// `text` with `from`, which it holds once, replaced by `to`.
fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "{from}");
    text.replacen(from, to, 1)
}
