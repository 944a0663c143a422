//! Imported scenes through the real GL pipeline: the Cornell box written in
//! pbrt-v4 and in Mitsuba 3 (scenes/tests/import/, with PLY and OBJ copies
//! of its meshes) renders as scenes/cornell_box_obj.toml does, and the pbrt
//! stack of transforms renders as its flattened TOML. "As" means within the
//! two renders' noise, measured from their seed-to-seed spread
//! (`common::block_chi2`); each comparison also shows it tells a scene with
//! a 10% brighter light apart.

use crate::common;

use std::path::{Path, PathBuf};

use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::import::{convert_bytes, format_of, Disk, ImportOptions};
use photonmap::scene::{load_scene, load_scene_str, Scene};

const SEEDS: u32 = 8;

fn fixture(name: &str) -> PathBuf {
    common::root().join("scenes/tests/import").join(name)
}

/// A fixture converted from `text` (its own file's, or edited) and loaded.
fn imported(name: &str, edit: impl Fn(String) -> String) -> Scene {
    let path = fixture(name);
    let text = edit(std::fs::read_to_string(&path).unwrap());
    let format = format_of(&path).unwrap();
    let c = convert_bytes(
        format,
        text.as_bytes(),
        &path,
        &Disk,
        &ImportOptions::default(),
    )
    .unwrap();
    load_scene_str(&c.toml, Path::new(name)).unwrap()
}

/// `SEEDS` renders at w x h from seed `first` on, with `like`'s photon-map
/// and render parameters (so that only the scenes' own contents differ).
fn renders(scene: &Scene, like: &Scene, (w, h): (u32, u32), first: u32) -> Vec<Image> {
    let gpu = common::gpu();
    let mut scene = scene.clone();
    scene.photon_map = like.photon_map.clone();
    scene.render = like.render.clone();
    (0..SEEDS)
        .map(|seed| {
            let mut o = RenderOptions::for_scene(&scene);
            (o.width, o.height, o.seed) = (w, h, first + seed);
            render(&gpu, &scene, &o, &mut ()).unwrap().image
        })
        .collect()
}

fn agree(what: &str, a: &[Image], b: &[Image], wrong: &[Image], block: u32) {
    let (chi2, blocks, bound) = common::block_chi2(a, b, block);
    let (chi2_wrong, _, _) = common::block_chi2(a, wrong, block);
    eprintln!("{what}: chi^2/n = {chi2:.2} over {blocks} blocks (bound {bound:.2}); against the brighter light {chi2_wrong:.1}");
    assert!(chi2 <= bound, "{what}: chi^2/n = {chi2} > {bound}");
    assert!(
        chi2_wrong > bound,
        "{what}: the brighter light was not told apart ({chi2_wrong})"
    );
}

/// The OBJ Cornell box, with a photon map small enough for 32 x 32 renders.
fn obj_cornell() -> Scene {
    let mut s = load_scene(&common::root().join("scenes/cornell_box_obj.toml")).unwrap();
    s.photon_map.photons_stored = 8000;
    s.photon_map.k = 50;
    s.render.shadow_rays = 4;
    s
}

#[test]
fn the_pbrt_and_mitsuba_cornell_boxes_render_as_the_obj_one() {
    let obj = obj_cornell();
    let size = (32, 32);
    let reference = renders(&obj, &obj, size, 100);
    let brighter = |t: String| common::replace_once(&t, "17 12 4", "18.7 13.2 4.4");
    let pbrt = renders(&imported("cornell_box.pbrt", |t| t), &obj, size, 200);
    let pbrt_bright = renders(&imported("cornell_box.pbrt", brighter), &obj, size, 300);
    agree("pbrt Cornell box", &pbrt, &reference, &pbrt_bright, 4);
    let xml_bright = |t: String| common::replace_once(&t, "17, 12, 4", "18.7, 13.2, 4.4");
    let xml = renders(&imported("cornell_box.xml", |t| t), &obj, size, 400);
    let xml_wrong = renders(&imported("cornell_box.xml", xml_bright), &obj, size, 500);
    agree("Mitsuba Cornell box", &xml, &reference, &xml_wrong, 4);
}

#[test]
fn a_stack_of_pbrt_transforms_renders_as_its_flattened_toml() {
    let mut flat = load_scene(&fixture("transforms_flat.toml")).unwrap();
    flat.photon_map.photons_stored = 3000;
    let size = (32, 24);
    let reference = renders(&flat, &flat, size, 100);
    let pbrt = renders(&imported("transforms.pbrt", |t| t), &flat, size, 200);
    let brighter = |t: String| common::replace_once(&t, "[ 4 4 4 ]", "[ 4.4 4.4 4.4 ]");
    let wrong = renders(&imported("transforms.pbrt", brighter), &flat, size, 300);
    agree("pbrt transforms", &pbrt, &reference, &wrong, 4);
}
