//! Each paper scene at reduced size against its stored reference, Mitsuba-style:
//! reference_images/<scene>.exr is the mean of SEEDS renders and <scene>.var.exr
//! the per-pixel variance of one render (plus the squared difference between two
//! llvmpipe SIMD widths, LP_NATIVE_VECTOR_WIDTH=128 vs default, for driver
//! rounding). A render is scored by the fraction of pixel channels whose
//! z = (x - mean) / sqrt(var (1 + 1/SEEDS) + floor^2) exceeds 4 in magnitude. The
//! tolerance on that fraction is measured, not chosen: each seed scored against
//! the other seeds' mean and variance (leave-one-out), mean + 4 sigma.
//! floor = 1e-3 x the mean + 1e-6: a rounding allowance for pixels that no seed
//! changes (a point light's shadow edge), far below any visible change.
//! Regenerate only on purpose: PHOTONMAP_REGENERATE_REFERENCES=1 cargo test --release --test gpu reference_images

use crate::common::{self, Run};

use std::path::PathBuf;

use photonmap::regress::{make_reference, Reference, Tolerance};
use photonmap::render::{render, Image, RenderOptions};
use photonmap::scene::{Light, Scene};

const SCENES: [&str; 3] = ["glass_ball", "ring", "cornell_box"];
const SEEDS: u32 = 16;
/// Not among the seeds the reference averages.
const TEST_SEED: u32 = 1000;
const REDUCTION: u32 = 4;

fn reduced(scene: &Scene) -> RenderOptions {
    let mut o = RenderOptions::for_scene(scene);
    o.width = scene.camera.width / REDUCTION;
    o.height = scene.camera.height / REDUCTION;
    o
}

fn render_seed(gpu: &photonmap::gpu::Gpu, scene: &Scene, seed: u32) -> Image {
    let mut o = reduced(scene);
    o.seed = seed;
    render(gpu, scene, &o, &mut ()).unwrap().image
}

fn dir() -> PathBuf {
    common::root().join("reference_images")
}

/// The same render from the binary in a fresh process with another SIMD width.
fn render_with_narrow_simd(name: &str, o: &RenderOptions, seed: u32) -> Image {
    let d = common::TempDir::new("simd");
    let (png, out) = (d.join(format!("{name}.png")), d.join(format!("{name}.exr")));
    Run::new(["render", "--quiet", "--seed", &seed.to_string()])
        .args(["--width", &o.width.to_string()])
        .args(["--height", &o.height.to_string()])
        .scene(name)
        .output_to(&png)
        .writing("--exr", &out)
        .env("LP_NATIVE_VECTOR_WIDTH", "128")
        .succeeds();
    Image::read_exr(&out).unwrap()
}

fn regenerate(gpu: &photonmap::gpu::Gpu, name: &str) {
    let scene = common::paper_scene(name);
    let images: Vec<Image> = (1..=SEEDS).map(|s| render_seed(gpu, &scene, s)).collect();
    let o = reduced(&scene);
    let narrow = render_with_narrow_simd(name, &o, 1);
    let tol = Tolerance {
        scene: name.into(),
        width: o.width,
        height: o.height,
        seeds: SEEDS,
        renderer: gpu.capabilities().gl_renderer,
        loo_fail_mean: 0.0,
        loo_fail_std: 0.0,
        driver_rmse: 0.0,
        tolerance: 0.0,
        command:
            "PHOTONMAP_REGENERATE_REFERENCES=1 cargo test --release --test gpu reference_images"
                .into(),
    };
    let r = make_reference(&images, &narrow, tol).unwrap();
    r.write(&dir(), name).unwrap();
    eprintln!("regenerated {name}: {:?}", r.tol);
}

/// Regenerates every reference once per process when asked, before anyone reads them.
fn ensure_references(gpu: &photonmap::gpu::Gpu) {
    static ONCE: std::sync::Mutex<bool> = std::sync::Mutex::new(false);
    let mut done = ONCE.lock().unwrap_or_else(|p| p.into_inner());
    if !*done && std::env::var_os("PHOTONMAP_REGENERATE_REFERENCES").is_some() {
        for name in SCENES {
            regenerate(gpu, name);
        }
    }
    *done = true;
}

fn load(name: &str) -> Reference {
    let hint = "regenerate with PHOTONMAP_REGENERATE_REFERENCES=1";
    Reference::load(&dir(), name).unwrap_or_else(|e| panic!("{e}: {hint}"))
}

/// Each scene with its reference (regenerated first when asked), loaded as
/// the loop reaches it.
fn references(gpu: &photonmap::gpu::Gpu) -> impl Iterator<Item = (&'static str, Reference)> {
    ensure_references(gpu);
    SCENES.into_iter().map(|name| (name, load(name)))
}

/// Scores a render; the actual image and its |z| map go to target/ for a look.
fn score(label: &str, actual: &Image, r: &Reference) -> f64 {
    let dir = common::root().join("target").join("reference-images");
    std::fs::create_dir_all(&dir).unwrap();
    common::write_exr(&dir.join(format!("{label}.actual.exr")), actual);
    let mut diff = actual.clone();
    for (d, m) in diff.pixels.iter_mut().zip(&r.mean.pixels) {
        for c in 0..3 {
            d[c] = (d[c] - m[c]).abs();
        }
    }
    common::write_exr(&dir.join(format!("{label}.diff.exr")), &diff);
    r.failing_fraction(actual)
}

#[test]
fn paper_scenes_match_their_references() {
    let gpu = common::gpu();
    for (name, r) in references(&gpu) {
        let scene = common::paper_scene(name);
        let actual = render_seed(&gpu, &scene, TEST_SEED);
        assert!(!actual.has_non_finite(), "{name}: NaN or Inf in the image");
        let f = score(name, &actual, &r);
        eprintln!(
            "{name}: {:.4}% of channels beyond |z| = 4 (tolerance {:.4}%, seeds {:.4}% +- {:.4}%)",
            100.0 * f,
            100.0 * r.tol.tolerance,
            100.0 * r.tol.loo_fail_mean,
            100.0 * r.tol.loo_fail_std
        );
        assert!(f <= r.tol.tolerance, "{name}: {f} of channels fail the z-test, tolerance {}; images in target/reference-images/", r.tol.tolerance);
    }
}

/// A render of `name` with a defect, `(label, as the report names it, as the
/// failure names it)`, must fail the comparison.
fn assert_caught(
    name: &str,
    (label, defect, what): (&str, &str, &str),
    img: &Image,
    r: &Reference,
) {
    let f = score(&format!("{name}.{label}"), img, r);
    eprintln!(
        "{name}: {defect} fails {:.3}% (tolerance {:.3}%)",
        100.0 * f,
        100.0 * r.tol.tolerance
    );
    assert!(
        f > r.tol.tolerance,
        "{name}: {what} passed ({f}, tolerance {})",
        r.tol.tolerance
    );
}

/// The comparison can fail: a 10% brighter light, a camera one pixel off, and
/// (where there is one) a missing caustic.
#[test]
fn the_comparison_catches_defects() {
    let gpu = common::gpu();
    for (name, r) in references(&gpu) {
        let mut bright = common::paper_scene(name);
        for l in &mut bright.lights {
            match l {
                Light::Area { radiance, .. } => *radiance *= 1.1,
                Light::Point { intensity, .. } => *intensity *= 1.1,
                Light::Triangles { radiance, .. } => *radiance *= 1.1,
            }
        }
        for m in &mut bright.materials {
            if let photonmap::scene::Material::Emitter { radiance, .. } = m {
                *radiance *= 1.1;
            }
        }
        let img = render_seed(&gpu, &bright, TEST_SEED);
        let defect = ("brighter", "brighter light", "a 10% brighter light");
        assert_caught(name, defect, &img, &r);

        let mut shifted = common::paper_scene(name);
        let o = reduced(&shifted);
        let (u, _, _) = shifted.camera.basis();
        // One pixel to the right, at the look-at distance.
        let dist = (shifted.camera.look_at - shifted.camera.position).length();
        let pixel =
            2.0 * dist * (shifted.camera.vfov_degrees.to_radians() * 0.5).tan() / o.height as f32;
        shifted.camera.position += u * pixel;
        shifted.camera.look_at += u * pixel;
        let img = render_seed(&gpu, &shifted, TEST_SEED);
        let defect = ("shifted", "shifted camera", "a camera one pixel off");
        assert_caught(name, defect, &img, &r);
        if name != "cornell_box" {
            // In these two scenes the floor is the only diffuse surface and
            // nothing above it is diffuse, so every stored photon is a caustic
            // photon: without the caustic, the render is direct light only.
            let scene = common::paper_scene(name);
            let mut o = reduced(&scene).direct_only();
            o.seed = TEST_SEED;
            let img = render(&gpu, &scene, &o, &mut ()).unwrap().image;
            let defect = (
                "no_caustic",
                "missing caustic",
                "a render without its caustic",
            );
            assert_caught(name, defect, &img, &r);
        }
    }
}
