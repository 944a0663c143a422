//! The restructure of issue 12 (and any later change that claims to move code
//! without changing an algorithm) must leave images bit for bit as they were.
//! reference_images/bit_identical/ holds renders made by the code before the
//! move, at reduced size, on llvmpipe: the three paper scenes at one sample per
//! pixel with the bitonic build, GLASS BALL with two samples and stencil
//! routing, and CORNELL BOX under --faithful (random-number texture, float
//! addressing, no compaction). The three paper scenes are drawn again with
//! the counting build, which must give the bitonic build's images. Each is compared exactly, every f32 of every
//! pixel: this is the one image test that demands equality, because it tests a
//! claim of equality (same driver, same seed). A different driver is reported,
//! not excused.
//! They were drawn with 8 shadow samples a pass; the default batch (one pass
//! at these sizes) is checked to differ from that by f32 rounding alone.
//!
//! The comparison is opt-in: another driver (another Mesa, LLVM or SIMD
//! width, or a GPU) rounds differently and fails it by design, so it runs
//! only with `PHOTONMAP_BIT_IDENTICAL=1` set, on the driver the images were
//! made on (llvmpipe, LLVM 15, 256 bits):
//! PHOTONMAP_BIT_IDENTICAL=1 cargo test --release --test gpu bit_identical
//! Without it the test says in one line that it was skipped. Regenerate only
//! on purpose:
//! PHOTONMAP_REGENERATE_REFERENCES=1 cargo test --release --test gpu bit_identical

use crate::common;

use std::path::PathBuf;

use std::io::Write;

use photonmap::photon::BuildMethod;
use photonmap::render::{render, Image, RenderOptions};

struct Case {
    file: &'static str,
    scene: &'static str,
    spp: u32,
    build: BuildMethod,
    faithful: bool,
}

const CASES: [Case; 8] = [
    Case {
        file: "glass_ball",
        scene: "glass_ball",
        spp: 1,
        build: BuildMethod::Bitonic,
        faithful: false,
    },
    Case {
        file: "ring",
        scene: "ring",
        spp: 1,
        build: BuildMethod::Bitonic,
        faithful: false,
    },
    Case {
        file: "cornell_box",
        scene: "cornell_box",
        spp: 1,
        build: BuildMethod::Bitonic,
        faithful: false,
    },
    Case {
        file: "glass_ball_spp2_stencil",
        scene: "glass_ball",
        spp: 2,
        build: BuildMethod::Stencil,
        faithful: false,
    },
    Case {
        file: "cornell_box_faithful",
        scene: "cornell_box",
        spp: 1,
        build: BuildMethod::Bitonic,
        faithful: true,
    },
    // The counting build makes the bitonic build's map bit for bit on
    // llvmpipe, so it draws the bitonic images (compared, never written).
    Case {
        file: "glass_ball",
        scene: "glass_ball",
        spp: 1,
        build: BuildMethod::Counting,
        faithful: false,
    },
    Case {
        file: "ring",
        scene: "ring",
        spp: 1,
        build: BuildMethod::Counting,
        faithful: false,
    },
    Case {
        file: "cornell_box",
        scene: "cornell_box",
        spp: 1,
        build: BuildMethod::Counting,
        faithful: false,
    },
];

fn path(file: &str) -> PathBuf {
    common::root()
        .join("reference_images/bit_identical")
        .join(format!("{file}.exr"))
}

fn render_case(gpu: &photonmap::gpu::Gpu, c: &Case) -> Image {
    let scene = common::paper_scene(c.scene);
    let mut o = RenderOptions::for_scene(&scene);
    o.width = scene.camera.width / 4;
    o.height = scene.camera.height / 4;
    o.seed = 7;
    o.spp = c.spp;
    // The stored images were drawn pass by pass, 8 shadow samples a pass;
    // the default batch and the fused eye path add the same samples in
    // another order (the test below, and tests/gpu/fused_eye_path.rs).
    o.shadow_batch = 8;
    o.pass_per_bounce = true;
    let gi = o.photon_map_mut().unwrap();
    gi.photons.build = c.build;
    gi.photons.faithful = c.faithful;
    render(gpu, &scene, &o, &mut ()).unwrap().image
}

/// Where the stored images were rendered; only there can they be equalled.
const RECORDED_ON: &str = "llvmpipe, LLVM 15, 256 bits";

#[test]
fn paper_scenes_render_bit_identical_to_before_the_move() {
    let regenerate = std::env::var_os("PHOTONMAP_REGENERATE_REFERENCES").is_some();
    if !regenerate && std::env::var_os("PHOTONMAP_BIT_IDENTICAL").is_none() {
        // Straight to stderr, past libtest's capture: the skip is seen.
        let _ = writeln!(
            std::io::stderr(),
            "bit_identical: skipped (set PHOTONMAP_BIT_IDENTICAL=1 to compare; the stored images were made on {RECORDED_ON})"
        );
        return;
    }
    let gpu = common::gpu();
    let renderer = gpu.capabilities().gl_renderer;
    let mut differing = Vec::new();
    for c in &CASES {
        let img = render_case(&gpu, c);
        let p = path(c.file);
        if regenerate {
            if c.build != BuildMethod::Counting {
                common::write_exr(&p, &img);
            }
            continue;
        }
        let stored = Image::read_exr(&p).unwrap();
        assert_eq!((stored.width, stored.height), (img.width, img.height));
        let changed = common::channels_differing(&img, &stored);
        if changed > 0 {
            differing.push(format!(
                "{} ({}): {changed} channels differ",
                c.file, c.build
            ));
        }
    }
    assert!(
        differing.is_empty(),
        "not bit-identical on {renderer}: {differing:?} (the stored images were made on {RECORDED_ON})"
    );
}

/// One pass of all 32 shadow samples (the default at this size) sums the same
/// samples as four passes of 8 in another order: equal up to f32 rounding.
#[test]
fn the_shadow_batch_changes_only_the_order_of_the_sum() {
    let gpu = common::gpu();
    let c = &CASES[2];
    let batched = render_case(&gpu, c);
    let scene = common::paper_scene(c.scene);
    let mut o = RenderOptions::for_scene(&scene);
    (o.width, o.height, o.seed) = (scene.camera.width / 4, scene.camera.height / 4, 7);
    assert_eq!(o.shadow_batch, 0, "the default batch is chosen by size");
    o.pass_per_bounce = true; // batches are the pass per bounce's
    let whole = render(&gpu, &scene, &o, &mut ()).unwrap().image;
    let mut changed = 0;
    for (a, b) in whole
        .pixels
        .iter()
        .flatten()
        .zip(batched.pixels.iter().flatten())
    {
        // f32 sums of 32 terms in two orders: a few ulps of the largest.
        assert!(
            (a - b).abs() <= 1e-5 * a.abs().max(b.abs()) + 1e-30,
            "{a} against {b}"
        );
        changed += (a != b) as usize;
    }
    eprintln!("{changed} channels differ by rounding");
}
